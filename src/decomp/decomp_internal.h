/* decomp_internal.h - the representation behind vw_decomp (kd-tree, cell boxes,
 * neighbour lists), shared by the decomposition and balancing sources.
 */
#ifndef VW_DECOMP_INTERNAL_H
#define VW_DECOMP_INTERNAL_H

#include "vwalls/decomp.h"

#include <stdatomic.h>
#include <stdint.h>

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
    /* Who this decomposition is known to equal: the number its constructor drew, or that
       of another decomposition that vw_decomp_equal found equal to it (a clone, first).
       Two decompositions with the same number are equal, so vw_decomp_equal answers
       them at once, where comparing the trees costs a pass over every node (once per
       cell built, in the ray tracer). Numbers are never reused (64 bits), and only ever
       copied between equal decompositions, so the answer is sound even if the one that
       drew the number is freed. Atomic: vw_decomp_equal writes it from worker threads. */
    _Atomic uint64_t same_as;
};

/* Divides cell `cell` of a kd-tree node array of n nodes (with room for two more) by a
   wall at `split` across `axis`: the cell's leaf becomes the wall, its low side keeps the
   cell, its high side is the new cell `newcell`. Returns the new node count, n + 2 (n
   when no leaf holds the cell). For vw_decomp_create_kd: divide (balancing) and the
   collider's split per process. */
int vw__kd_divide(vw_kd_node *nodes, int n, int cell, int axis, double split, int newcell);

#endif
