/* vwalls/decomp.h - decompositions of the world box into cells by virtual walls.
 *
 * Every decomposition is a kd-tree of axis-aligned splits ("walls") over the world box,
 * expressed in a decomposition frame: frame coordinates are p' = F p for an orthonormal
 * 3x3 matrix F (identity unless the balancer rotated the frame). Points, rays and object
 * bounds are given in world coordinates; cell boxes are in frame coordinates.
 *
 * Invariants: the leaves ("cells") tile the world box with no gap or overlap; a point on
 * a wall belongs to the cell on the side its direction points to (+ side when the
 * direction is zero along that axis); the segments of a ray walk are contiguous: the
 * exit parameter of one cell is, as the same double, the entry parameter of the next,
 * so a ray's t-interval is split the same way wherever the walk is restarted.
 */
#ifndef VWALLS_DECOMP_H
#define VWALLS_DECOMP_H

#include "vwalls/common.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VW_MAX_CELLS 32768

typedef struct vw_decomp vw_decomp;

typedef enum vw_decomp_kind {
    VW_DECOMP_GRID = 0,      /* global walls per axis: one neighbour per face */
    VW_DECOMP_STAGGERED = 1, /* x slabs, y cuts per slab, z cuts per column */
    VW_DECOMP_DIVIDED = 2    /* any kd-tree, e.g. a grid with divided cells */
} vw_decomp_kind;

VW_API const char *vw_decomp_kind_name(vw_decomp_kind k);

/* One node of a kd-tree description. axis < 0 marks a leaf holding cell `cell`;
   otherwise points with p[axis] < split go to `left`, the others to `right`.
   Node 0 is the root. Cell ids must be exactly 0..ncells-1, each once. */
typedef struct vw_kd_node {
    int axis;
    double split;
    int left, right;
    int cell;
} vw_kd_node;

/* "4", "2x4", "2x2x2" -> dims (missing dimensions are 1). On VW_E_INPUT dims are 1x1x1
   and err gets a one-line message. */
VW_API vw_status vw_layout_parse(const char *s, int dims[3], char *err, size_t errlen);

/* A grid with uniform walls. Cell id of grid index (i,j,k) is i + nx*(j + ny*k). */
VW_API vw_status vw_decomp_create_grid(const vw_box *world, const int dims[3], vw_decomp **out);
/* A grid with given walls: walls[a] holds dims[a]-1 increasing interior positions (frame
   coordinates); frame is a row-major 3x3 orthonormal matrix or NULL for identity, and
   world is then the box in frame coordinates. */
VW_API vw_status vw_decomp_create_grid_walls(const vw_box *world, const int dims[3],
                                             const double *const walls[3], const double *frame,
                                             vw_decomp **out);
/* Any kd-tree. world is in frame coordinates; frame may be NULL (identity). kind is
   VW_DECOMP_STAGGERED or VW_DECOMP_DIVIDED: a grid is made by the two calls above, which
   record its walls per axis (VW_E_INVAL for any other kind, or a frame that is not
   orthonormal). */
VW_API vw_status vw_decomp_create_kd(const vw_box *world, const vw_kd_node *nodes, int nnodes,
                                     const double *frame, vw_decomp_kind kind, vw_decomp **out);
VW_API vw_status vw_decomp_clone(const vw_decomp *d, vw_decomp **out);
/* 1 when a and b have the same world box, frame and kd-tree (walls and cell ids): every
   query then answers the same on both, bit for bit. Lets a caller keep results computed
   on one decomposition (who owns which eye ray) until the walls move. */
VW_API int vw_decomp_equal(const vw_decomp *a, const vw_decomp *b);
VW_API void vw_decomp_free(vw_decomp *d);

VW_API vw_decomp_kind vw_decomp_get_kind(const vw_decomp *d);
VW_API int vw_decomp_cell_count(const vw_decomp *d);
/* Grid dims; for other kinds {cells, 1, 1}. */
VW_API void vw_decomp_dims(const vw_decomp *d, int dims[3]);
/* "2x2x2" for grids, else the cell count; into buf. */
VW_API void vw_decomp_layout_string(const vw_decomp *d, char *buf, size_t len);
/* Interior wall positions of a grid along axis (dims[axis]-1 values); NULL otherwise. */
VW_API const double *vw_decomp_grid_walls(const vw_decomp *d, int axis);
VW_API vw_box vw_decomp_world(const vw_decomp *d);
/* A cell's box; for an id outside 0 .. vw_decomp_cell_count() - 1 the empty box at the
   origin (lo = hi = 0), which is no error: check ids against the count first. */
VW_API vw_box vw_decomp_cell_box(const vw_decomp *d, int cell);
/* The kd-tree nodes (for balancers that edit a decomposition). */
VW_API const vw_kd_node *vw_decomp_nodes(const vw_decomp *d, int *nnodes);
/* Row-major world->frame rotation; NULL when the frame is the identity. */
VW_API const double *vw_decomp_frame(const vw_decomp *d);
VW_API void vw_decomp_to_frame(const vw_decomp *d, const double p[3], double out[3]);
/* The inverse: frame point q in world coordinates (F^T q, the frame being orthonormal). */
VW_API void vw_decomp_from_frame(const vw_decomp *d, const double q[3], double out[3]);
/* Bounds in frame coordinates of a world-coordinate box (conservative under rotation). */
VW_API void vw_decomp_box_to_frame(const vw_decomp *d, const vw_box *b, vw_box *out);

/* The cell holding world point p; dir decides points on walls (may be NULL): a point
   on a wall goes to the side dir points to, and to the upper side when dir is NULL or
   parallel to the wall. The world box is closed: a point on its upper face belongs to
   the last cell along that axis. -1 when p lies outside the world box. */
VW_API int vw_decomp_locate(const vw_decomp *d, const double p[3], const double dir[3]);

typedef struct vw_segment {
    int cell;
    double t0, t1;   /* the ray is inside cell for t in [t0, t1] */
} vw_segment;
/* Return 0 from the visitor to stop the walk. */
typedef int (*vw_segment_fn)(const vw_segment *seg, void *user);
/* Visits, in order of increasing t, every cell that the ray o + t d (world coordinates)
   crosses for t in [t0, t1] (t1 may be INFINITY), with non-empty parameter intervals.
   Returns the number of segments visited. */
VW_API int vw_decomp_walk(const vw_decomp *d, const double o[3], const double dir[3],
                          double t0, double t1, vw_segment_fn fn, void *user);
/* The first segment of that walk; returns 0 when the ray misses the world. */
VW_API int vw_decomp_first_segment(const vw_decomp *d, const double o[3], const double dir[3],
                                   double t0, double t1, vw_segment *out);
/* The cell whose walk every ray o + t v starts in, for every v in the cone that the n
   directions dirs span (their non-negative combinations), when that can be shown
   cheaply: o lies inside the world box, away from the walls of its cell (that cell,
   whatever the cone); or all of the rays enter the world box through one face, inside
   one cell's piece of it, away from its edges and walls. -1 when it cannot (o lies on
   or near a wall, the cone meets a wall or an edge of the world box, or misses it):
   ask per ray. For the pixels of an image tile this answers for the whole tile from
   its four corners' rays. */
VW_API int vw_decomp_cone_cell(const vw_decomp *d, const double o[3], const double (*dirs)[3],
                               int n);
/* A walk in two halves, for a ray that crosses many walls: vw_decomp_clip narrows
   [*t0, *t1] to the world box (returns 0 when nothing is left), and on a clipped
   interval, or one that starts at the t1 of one of its segments and ends where the
   clipped one does, vw_decomp_next_segment gives the same segment as
   vw_decomp_first_segment, bit for bit, without clipping again: that saves most of
   the cost of a wall crossing. Returns 0 when t0 >= t1. */
VW_API int vw_decomp_clip(const vw_decomp *d, const double o[3], const double dir[3],
                          double *t0, double *t1);
VW_API int vw_decomp_next_segment(const vw_decomp *d, const double o[3], const double dir[3],
                                  double t0, double t1, vw_segment *out);

/* A ray walk carried by its caller, one cell at a time: the incremental form of
   vw_decomp_walk, for a ray that is searched cell by cell (the ray tracer). It keeps,
   per axis, where the ray leaves the current cell through an inner wall, so crossing
   into a neighbour that has the same extent on the other two axes (every face of a
   grid) costs one division; other crossings descend from the root. Every segment is,
   bit for bit, the one vw_decomp_walk gives. */
typedef struct vw_walk {
    double q[3], v[3]; /* the ray in frame coordinates */
    double exit[3];    /* per axis: the parameter of the cell's far wall, INFINITY when
                          that wall is the world's or the ray runs parallel to it */
    double tmax;       /* the end of the walk, clipped to the world */
    vw_segment seg;    /* the current segment */
} vw_walk;
/* Starts the walk of o + t dir over [t0, t1] (world coordinates; t1 may be INFINITY):
   clips it and finds its first segment. Returns 0 when the ray misses the world. */
VW_API int vw_walk_start(const vw_decomp *d, vw_walk *w, const double o[3],
                         const double dir[3], double t0, double t1);
/* Resumes a walk whose current segment `seg` is known (a ray received in a message: its
   segment, and tmax, come from a walk of the same decomposition). */
VW_API void vw_walk_resume(const vw_decomp *d, vw_walk *w, const double o[3],
                           const double dir[3], const vw_segment *seg, double tmax);
/* Steps to the segment after the current one; 0 when the walk is over (w->seg is then
   unchanged). */
VW_API int vw_walk_next(const vw_decomp *d, vw_walk *w);

/* Faces: 0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z (in frame coordinates). */
#define VW_FACE_AXIS(f) ((f) >> 1)
#define VW_FACE_SIGN(f) (((f) & 1) ? 1 : -1)
/* The cells sharing a piece of face `face` of `cell` (positive area). Writes at most max
   ids; returns the total number (a face may have several neighbours, or none). An
   unknown cell or a face outside 0..5 has none: 0, as a face on the world's wall. */
VW_API int vw_decomp_neighbours(const vw_decomp *d, int cell, int face, int *out, int max);
/* The largest number of neighbours any cell has over all faces. */
VW_API int vw_decomp_max_neighbours(const vw_decomp *d);
/* All cells in front-to-back order as seen from world point p (near side of every
   split first). order must hold vw_decomp_cell_count() ids. */
VW_API void vw_decomp_front_to_back(const vw_decomp *d, const double p[3], int *order);
/* The cells whose box overlaps world box b (after transforming it to the frame), each
   box widened by pad. Writes at most max ids, returns the total number. */
VW_API int vw_decomp_cells_overlapping(const vw_decomp *d, const vw_box *b, double pad,
                                       int *out, int max);

#ifdef __cplusplus
}
#endif
#endif
