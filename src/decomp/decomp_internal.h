/* decomp_internal.h - the representation behind vw_decomp (kd-tree, cell boxes,
 * neighbour lists), shared by the decomposition and balancing sources.
 */
#ifndef VW_DECOMP_INTERNAL_H
#define VW_DECOMP_INTERNAL_H

#include "vwalls/decomp.h"

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
};

#endif
