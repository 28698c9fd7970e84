/* radiosity.h - the distributed progressive radiosity solver (docs/radiosity.md), as an
 * application of the public vwalls API: meshing, the vwalls module, the solve loop, the
 * hemicube and the outputs. Every name here is rad_*; nothing outside apps/ and tools/
 * uses it.
 *
 * Invariants the whole application keeps:
 *  - a piece (a patch clipped at the walls) lies in exactly one cell, its owner, the cell
 *    vw_decomp_locate() gives for its centroid with its normal as direction; every other
 *    cell the runtime hands it to drops it;
 *  - every piece and element is convex (the rasterisers fill a polygon by its edge
 *    functions, rad_poly_area's centroid is a fan): rad_mesh_build splits concave
 *    polygons into convex parts;
 *  - no geometry leaves its cell: a shot travels as a header plus a hemicube coverage
 *    bitmap, results travel to the output process as numbers;
 *  - energy ledger (per RGB channel, double): emitted = absorbed + unshot + escaped.
 */
#ifndef RAD_RADIOSITY_H
#define RAD_RADIOSITY_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/vwalls.h"

/* Largest number of vertices of a piece or element after clipping. A convex input
   polygon of up to RAD_MAXV-10 vertices always fits (a rectangle adds at most 4, a
   box at most 6); the mesher hands over no other (larger polygons in convex chunks,
   concave ones in convex parts). */
#define RAD_MAXV 24
/* Hemicube resolution limit: a shot message (header + 3 res^2 bits) must fit into
   VW_MAX_MSG_BYTES. */
#define RAD_MAX_RES 100
/* The most squares of side --patch-size that meshing lays over the polygons (each
   becomes a patch where it meets one): about a gigabyte of patches. */
#define RAD_MAX_SQUARES (1 << 21)

/* The object handed to the runtime: one patch clipped to one cell (plain data). */
typedef struct rad_piece {
    int64_t id;             /* global piece id: index in the mesh */
    int32_t poly;           /* original polygon id (scene object id) */
    int32_t nv;
    int32_t pi, pj;         /* patch grid index in the polygon's (u,v) frame */
    double v[RAD_MAXV][3];
    double normal[3], centroid[3], area;
    /* The area of the whole patch (the polygon clipped to square (pi, pj)) this piece is
       part of: the stopping rule is about patches, whatever the walls cut (module.c,
       patch_unshot). Equals area when no wall cuts the patch. */
    double patch_area;
    double origin[3], uax[3], vax[3];  /* the polygon's frame: elements align to it */
    double elem;            /* level-0 receiver element size */
    double rho[3], emit[3]; /* reflectance; emitted radiosity (power per area) */
} rad_piece;

/* The default --stall-shots. A solve whose every shot loses (absorbs or lets escape)
   at least 1/RAD_STALL_SHOTS of its power cannot stall: each shot carries at least sf
   of the emitted power (the threshold; on one cell, where no wall cuts a patch), so a
   stretch of RAD_STALL_SHOTS shots loses at least sf of it. Only a scene reflecting more than 99.99 % of what it receives can
   stall, and a closed one with a reflectance of 1 in some channel does (nothing is
   absorbed there, so the unshot power only spreads). */
#define RAD_STALL_SHOTS 10000

typedef struct rad_options {
    double sf;              /* stop when max unshot / emitted < sf */
    int res;                /* hemicube resolution (even, <= RAD_MAX_RES) */
    double patch_size;      /* largest patch side; <= 0: from the scene size */
    int elem_split;         /* receiver elements per patch side */
    int workers;
    int dims[3];            /* grid layout of cells */
    int per_round;          /* shots per cell per round */
    double neighbourhood;   /* > 0: a shot reaches only cells within this distance */
    double subdivide;       /* > 0: adaptive subdivision threshold (relative) */
    int max_level;          /* deepest subdivision level (<= RAD_MAX_LEVEL) */
    int64_t max_shots;      /* > 0: stop after this many shots (not converged) */
    /* Stop, stalled, when less than sf of the emitted power (r+g+b) was absorbed or
       escaped over this many shots (solve.c, RAD_STALL_SHOTS; rad_solver_stalled). */
    int64_t stall_shots;
    int max_rounds;         /* > 0: stop after this many rounds (testing a kill) */
    const char *checkpoint; /* file to write checkpoints to, or NULL */
    double checkpoint_every;/* seconds between checkpoints (0: every round) */
    const char *resume;     /* checkpoint to resume from, or NULL */
    int quiet;
} rad_options;

void rad_options_init(rad_options *o);

/* ---- meshing (mesh.c) ---- */

typedef struct rad_mesh {
    rad_piece *pieces;
    size_t npieces;
    int *owner;             /* owner cell of each piece */
    size_t npolys;          /* scene polygons (ids are scene ids, may be sparse) */
    double emitted[3];      /* total emitted power */
    double area;            /* total area */
    double patch_size;      /* the patch side used (--patch-size or the scene's default) */
    /* Spheres and cones are meshed as facets (mesh.c, RAD_SPHERE_LON): polygon ids from
       facet_base on, facet_object[id - facet_base] the scene id of the sphere or cone
       (the CSV reports that object, summed over its facets). */
    int32_t facet_base;
    size_t nfacets;
    int32_t *facet_object;
} rad_mesh;

/* How many facets the scene's spheres and cones become (a fixed number each): with its
   polygons, the fewest pieces rad_mesh_build can make of it. */
double rad_mesh_facets(const vw_scene *s);

/* Splits every polygon, and the facets of every sphere and cone, into patches and clips
   them at the cells of d. Bad geometry is
   reported as "file:line: message" in err (VW_E_INPUT); zero-area polygons are skipped
   with a warning on stderr (unless quiet). A scene without emitter is an error. */
vw_status rad_mesh_build(const vw_scene *s, const char *path, const vw_decomp *d,
                         const rad_options *o, rad_mesh *m, char *err, size_t errlen);
void rad_mesh_free(rad_mesh *m);
/* The world box for a scene: its bounds, padded so that no axis is flat. */
vw_box rad_world_box(const vw_scene *s);
/* The default patch size for a scene (a tenth of the largest extent). */
double rad_default_patch_size(const vw_scene *s);
/* What the solver uses of a material (NULL: grey 0.5, no emission): the reflectance
   clamped to [0, 1], so that no surface gives back more than it receives, and the
   emission clamped to >= 0. The one definition for the mesher and the CSV. Returns 1
   when the reflectance had to be clamped (NaN counts, and becomes 0). */
int rad_material(const vw_material *mt, double rho[3], double emit[3]);
/* 1 when a reflectance the solver uses (rad_material's rho) is 1 in some channel: such
   a surface absorbs nothing of that channel, and a closed scene of them never loses
   the power it emits there (the mesher warns; the solve stops as stalled). */
int rad_reflects_all(const double rho[3]);

/* Geometry helpers shared with the module and the outputs. */
typedef struct rad_poly {
    int n;
    double v[RAD_MAXV][3];
} rad_poly;
/* Element (level, gi, gj) of piece pc: the piece clipped to the grid square. Returns the
   number of vertices (0 when empty, or when it covers no more than 1e-9 of the square:
   a sliver left by rounding where a piece edge lies on a grid line). */
int rad_elem_polygon(const rad_piece *pc, int level, int gi, int gj, rad_poly *out);
/* The range of level-0 element grid indices a piece covers. */
void rad_piece_grid(const rad_piece *pc, int lo[2], int hi[2]);
double rad_poly_area(const rad_poly *p, double normal[3], double centroid[3]);

/* Deepest subdivision level: receiver detail is accumulated on a grid of 4^level cells per
   level-0 element from the first shot on (module.c), so it bounds that memory. */
#define RAD_MAX_LEVEL 4

/* Memory of the solve, measured (peak RSS of the Cornell box at --elements 2 to 32 and
   --max-level 3 and 4, nineteenth session): a level-0 element with its vertices and
   hash entry about 300 bytes, a fine cell of --subdivide about 60. */
#define RAD_ELEM_BYTES 300.0
#define RAD_FINE_BYTES 60.0
/* Bytes the solver takes for the mesh's elements from its start, at least: every
   level-0 element and, with --subdivide, its 4^max_level fine cells; elements split
   during the solve come on top. *elements (may be NULL) gets the level-0 count (an
   upper bound for pieces that are not rectangles). */
double rad_mesh_solve_bytes(const rad_mesh *m, const rad_options *o, double *elements);

/* ---- hemicube (hemicube.c) ---- */

typedef struct rad_hemicube {
    int res;                /* top face res x res; four half sides res x res/2 */
    int npix;               /* 3 res^2: pixel layout in hemicube.c */
    double *dff;            /* delta form factor per pixel, normalised to sum 1 */
    double raw_sum;         /* their sum before normalising (about 1) */
} rad_hemicube;

vw_status rad_hemicube_init(rad_hemicube *h, int res);
void rad_hemicube_free(rad_hemicube *h);
/* Bytes of a coverage bitmap. */
size_t rad_hemicube_bitmap_bytes(int res);

/* The hemicube's x axis for a shooter of normal n: a direction perpendicular to n turned
   about it by an angle drawn from seed, so that the aliasing of successive shots of a
   patch does not line up. The seed of shot k of piece p is rad_shot_seed(p, k). */
void rad_hemicube_orientation(const double n[3], uint64_t seed, double u[3]);
static inline uint64_t rad_shot_seed(int64_t piece, int64_t shot)
{
    return (uint64_t)piece * 1000003u + (uint64_t)shot;
}

/* The pixel the direction x (hemicube coordinates, x[2] > 0) passes through, and its
   position on that pixel's face in pixel units (pixel (i, j) covers [i, i+1) x [j, j+1)).
   -1 when x is not in front of the shooter. */
int rad_hemicube_pixel(const rad_hemicube *h, const double x[3], double fxy[2]);
/* The direction (hemicube coordinates) through the centre of pixel px. */
void rad_hemicube_pixel_dir(const rad_hemicube *h, int px, double d[3]);

/* Rasterises a polygon given in hemicube coordinates (x, y along the orientation, z
   along the shooter normal; origin at the shooter) into a z-buffer: pixels whose bit in
   mask is clear and whose stored depth is larger take depth and id. stamp/cur mark the
   pixels written in this shot (depth is valid only where stamp == cur); when written is
   not NULL, the first write of pixel p in a shot also sets bit p of it (npix bits in
   64-bit words), so that the pixels written are found without visiting all npix.
   A polygon seen from behind (the origin on its back side) counts RAD_BACK_BIAS
   (relative) farther, so it loses a depth tie to one seen from the front (two-sided
   panels: two coincident polygons back to back). */
#define RAD_BACK_BIAS 1e-9
typedef struct rad_zbuf {
    double *depth;
    int32_t *owner;
    uint32_t *stamp;
    uint32_t cur;
    uint64_t *written;
} rad_zbuf;
void rad_hemicube_raster(const rad_hemicube *h, const double (*hv)[3], int nv, const uint8_t *mask,
                         rad_zbuf *z, int32_t id, double near_eps);

/* ---- the solver (module.c, solve.c) ---- */

/* One receiver element's result, gathered on the output process. */
typedef struct rad_elem_result {
    int64_t piece;
    int32_t poly, level, gi, gj;
    double area;
    double B[3];            /* radiosity */
    double incident[3];     /* power that arrived (front side) */
} rad_elem_result;

typedef struct rad_patch_result {
    int64_t piece;
    int64_t nshots;
    double unshot[3];
} rad_patch_result;

typedef struct rad_ledger {
    double emitted[3], absorbed[3], unshot[3], escaped[3];
    double error;           /* max over channels of |emitted - rest| / emitted (infinity
                               when a term is not a number) */
} rad_ledger;

typedef struct rad_solver rad_solver;

/* Called on the output process after every round with the state the cells reported at
   its start, i.e. as the round before left it: the unshot ratio and the shot count of
   that one moment (the shots of the round just run are in the next call, and in
   rad_solver_shots()). */
typedef void (*rad_progress_fn)(void *user, double unshot_ratio, int64_t shots);

/* Creates the world over a mesh (the mesh must outlive the solver). */
vw_status rad_solver_create(const rad_mesh *m, const vw_decomp *d, const rad_options *o,
                            rad_solver **out, char *err, size_t errlen);
void rad_solver_free(rad_solver *s);
/* Runs rounds until converged (or a limit of the options, or stalled: see
   rad_solver_stalled). *converged tells whether it converged. */
vw_status rad_solver_run(rad_solver *s, rad_progress_fn progress, void *user, int *converged,
                         char *err, size_t errlen);
/* 1 when the last rad_solver_run stopped because the solve stalled: over the last
   *span shots (about stall_shots, at least half, counted between two reports) only
   *lost of the emitted power (r+g+b, a fraction) was absorbed or escaped, less than sf,
   so the unshot power was only spread, not spent. Every process knows whether; span and lost
   are valid on the output process (may be NULL). */
int rad_solver_stalled(const rad_solver *s, int64_t *span, double *lost);
/* Gathers the results on the output process (elements sorted by piece, level, gi, gj).
   Collective under MPI, like run: every process calls it; the results, the ledger and
   the unshot ratio below are valid on the output process only. */
vw_status rad_solver_collect(rad_solver *s, char *err, size_t errlen);
const rad_elem_result *rad_solver_elements(const rad_solver *s, size_t *n);
const rad_patch_result *rad_solver_patches(const rad_solver *s, size_t *n);
rad_ledger rad_solver_ledger(const rad_solver *s);
int64_t rad_solver_shots(const rad_solver *s);
double rad_solver_unshot_ratio(const rad_solver *s);
vw_world *rad_solver_world(rad_solver *s);
/* Writes a checkpoint (collects first); atomic. Collective: every process calls it, the
   output process writes, and every process returns the write's status. */
vw_status rad_solver_checkpoint(rad_solver *s, const char *path, char *err, size_t errlen);
/* Writes the results of the last collect as a checkpoint (output process only; a no-op
   elsewhere): for a caller that has just collected. */
vw_status rad_solver_write_checkpoint(const rad_solver *s, const char *path, char *err, size_t errlen);
/* Snapshot hook: called after every round on every process (it may collect). */
typedef void (*rad_round_fn)(void *user, rad_solver *s, int round);
void rad_solver_on_round(rad_solver *s, rad_round_fn fn, void *user);
/* Messages and bytes of shots (for the bench). */
void rad_solver_traffic(const rad_solver *s, int64_t *shot_msgs, int64_t *shot_bytes,
                        int64_t *full_msgs);

/* Per original polygon: area-weighted radiosity and total incident power, indexed by
   polygon id (arrays of npoly entries, zero where a polygon has no element). */
void rad_polygon_sums(const rad_elem_result *e, size_t n, size_t npoly, double *area,
                      double (*B)[3], double (*incident)[3]);

/* ---- the full-matrix reference (reference.c) ---- */

/* Patch-to-patch hemicube form factors on one cell (a shot's, with the orientation of
   its first shot) and P = E + diag(rho) F^T P solved by Gauss-Seidel, P being the power
   leaving each patch. For the bench and the tests; dense, n^2 doubles for n pieces.
   Build the mesh on one cell, so that pieces are the progressive solver's shooters. */
typedef struct rad_reference {
    size_t n;               /* patches: the mesh's pieces */
    double (*P)[3];         /* power leaving each patch (emitted + reflected) */
    int sweeps;             /* Gauss-Seidel sweeps done */
    double change;          /* largest change in the last sweep / total emitted */
    double ff_s, solve_s;   /* seconds: form factors; Gauss-Seidel */
    size_t matrix_bytes;
} rad_reference;
/* Sweeps until change < tol (fails with VW_E_LIMIT after max_sweeps). world: the box
   the progressive solver would use (for its near-plane epsilon). */
vw_status rad_reference_solve(const rad_mesh *m, const vw_box *world, int res, double tol, int max_sweeps,
                              rad_reference *out, char *err, size_t errlen);
void rad_reference_free(rad_reference *r);
/* The solution as one result per piece (B = P / area), for rad_polygon_sums and
   rad_write_csv; free() it. NULL when out of memory. */
rad_elem_result *rad_reference_elements(const rad_mesh *m, const rad_reference *r);

/* ---- outputs (output.c) ---- */

/* PLY with vertex colours (radiosity averaged at shared vertices of a polygon, plus the
   display ambient term), atomic. */
vw_status rad_write_ply(const char *path, const rad_mesh *m, const rad_elem_result *e, size_t n,
                        const double ambient[3], char *err, size_t errlen);
vw_status rad_write_csv(const char *path, const rad_mesh *m, const vw_scene *sc,
                        const rad_elem_result *e, size_t n, char *err, size_t errlen);
/* Writes the picture in the format of its name (vw_image_format_of): .png 8-bit and
   tone mapped, .pfm float (the display radiosity, radiosity plus the ambient term, not
   tone mapped); VW_E_INVAL for another name. */
vw_status rad_write_image(const char *path, const vw_camera *cam, const rad_mesh *m,
                          const rad_elem_result *e, size_t n, const double ambient[3], char *err,
                          size_t errlen);
/* The display-only ambient term of progressive refinement (Cohen et al. 1988). */
void rad_ambient(const rad_mesh *m, const rad_patch_result *p, size_t np, double out[3]);

#endif
