/* decomp_internal.h - the representation behind vw_decomp (kd-tree, cell boxes,
 * neighbour lists), shared by the decomposition and balancing sources.
 */
#ifndef VW_DECOMP_INTERNAL_H
#define VW_DECOMP_INTERNAL_H

#include "vwalls/decomp.h"

/* A face a carried walk crosses in one step: it has one neighbour, flush with the cell on
   the other two axes (so the ray's exits along them stay the same); wall is that
   neighbour's far wall on the face's axis, in the face's direction, inner unless it is
   the world's. next is -1 for any other face. */
typedef struct vw_face_step {
    int next, inner;
    double wall;
} vw_face_step;

struct vw_decomp {
    vw_decomp_kind kind;
    vw_box world;          /* in frame coordinates */
    int has_frame;
    double frame[9];       /* world -> frame, row-major, orthonormal */
    int nnodes;
    vw_kd_node *nodes;     /* node 0 is the root */
    int ncells;
    vw_box *cell_box;      /* per cell, frame coordinates */
    int *cell_leaf;        /* per cell, its leaf node */
    int dims[3];           /* grid dims; {ncells,1,1} otherwise */
    double *walls[3];      /* grid: dims[a]-1 interior wall positions per axis */
    int *nb_start;         /* 6*ncells+1 offsets into nb, per (cell, face) */
    int *nb;
    int max_nb;
    vw_face_step *face_step; /* per (cell, face): the step of a carried walk (vw_walk_next) */
};

/* Divides cell `cell` of a kd-tree node array of n nodes (with room for two more) by a
   wall at `split` across `axis`: the cell's leaf becomes the wall, its low side keeps the
   cell, its high side is the new cell `newcell`. Returns the new node count, n + 2 (n
   when no leaf holds the cell). For vw_decomp_create_kd: divide (balancing) and the
   collider's split per process. */
int vw__kd_divide(vw_kd_node *nodes, int n, int cell, int axis, double split, int newcell);

#endif
