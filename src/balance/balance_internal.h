/* balance_internal.h - what the balancers share: the load field's representation and
 * the weighted-quantile cut that every wall-placing balancer uses.
 */
#ifndef VW_BALANCE_INTERNAL_H
#define VW_BALANCE_INTERNAL_H

#include "vwalls/balance.h"

/* The load field: point masses in world coordinates. A measured cell load becomes k^3
   points on a regular sub-grid of the cell, so "uniform inside the cell" is kept to
   within 1/k of the cell's width, and rotated frames need no special case. */
struct vw_load_field {
    size_t n, cap;
    double (*p)[3];
    double *w;
};

/* A point of the field in some frame, as the balancers sort and cut them. */
typedef struct vw__lpt {
    double x[3]; /* frame coordinates */
    double w;
} vw__lpt;

/* The field's points in the frame of d's frame matrix F (NULL = identity); *out is
   malloc'ed (NULL when the field is empty); returns the count or -1 without memory. */
long vw__field_points(const vw_load_field *f, const double *F, vw__lpt **out);

/* Wall positions cutting pts[0..n) along axis into `parts` pieces of equal load, inside
   [lo, hi], each piece at least minw wide, or, where minw is finer than the doubles
   there, one double: walls gets parts-1 values, lo < walls[0] < ... < hi. Returns 0 when
   that cannot be (fewer than parts-1 doubles lie strictly between lo and hi: the caller
   keeps the walls it has), else 1. Reorders pts (sorted along axis). */
int vw__cut(vw__lpt *pts, long n, int axis, double lo, double hi, int parts, double minw,
            double *walls);
/* vw__cut with the pieces' shares of the load: piece k gets share[k] / (sum of the
   shares) of it (share NULL: equal pieces, vw__cut). */
int vw__cut_shares(vw__lpt *pts, long n, int axis, double lo, double hi, int parts,
                   const double *share, double minw, double *walls);

/* Tensor walls in frame F over world box (frame coordinates) wb: walls[a] dims[a]-1.
   *fits 0 when some axis of wb is too thin for its cells (vw__cut). share: NULL (every
   cell an equal load), or each cell's wanted share of the load (dims[0] * dims[1] *
   dims[2] entries, cell i + nx (j + ny k)); a slab's share is the sum of its cells'. */
vw_status vw__tensor_walls(const vw_load_field *f, const double *F, const vw_box *wb,
                           const int dims[3], double minw_frac, const double *share,
                           double *walls[3], int *fits);

vw_status vw__balance_tensor(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp **out);
vw_status vw__balance_rotate(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp **out);
vw_status vw__balance_staggered(const vw_decomp *cur, const vw_load_field *f,
                                const vw_balance_params *p, const int dims[3], vw_decomp **out);
/* Tensor walls (kind VW_DECOMP_GRID: in cur's frame, over its world box) or a staggered
   decomposition (VW_DECOMP_STAGGERED) of dims whose cells get the shares of the load in
   share (as vw__tensor_walls), not equal ones: the mapping puts unequal numbers of cells
   on the workers (3 cells on 2 workers, 4 on 3) or the workers' speeds differ, and equal
   cells then leave lambda at (cells on the busiest worker) / (cells / workers). *out is
   NULL (VW_OK) where the walls do not fit (cells a few doubles wide). */
vw_status vw__balance_shaped(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, const int dims[3], vw_decomp_kind kind,
                             const double *share, vw_decomp **out);
/* The staggered half of vw__balance_shaped (staggered.c): slabs, columns and cells at
   their shares' quantiles; *out NULL where they do not fit. */
vw_status vw__staggered_shaped(const vw_decomp *cur, const vw_load_field *f,
                               const vw_balance_params *p, const int dims[3],
                               const double *share, vw_decomp **out);
/* Duplication plan on the current cells (load per cell, its master's worker): npairs
   copies (pair_cell[i] gets a copy on pair_worker[i]; arrays of max_extra entries) and
   the predicted lambda with each cell's load shared by its copies in proportion to
   their workers' speeds (equally when speeds is NULL), as the runtime shares it. */
vw_status vw__balance_duplicate_plan(const double *load, const int *cell_worker, int ncells,
                                     int gworkers, const double *speeds, double tolerance,
                                     int max_extra, int *pair_cell, int *pair_worker, int *npairs,
                                     double *lambda);
vw_status vw__balance_divide(const vw_decomp *cur, const vw_load_field *f,
                             const vw_balance_params *p, vw_decomp **out, int *cell_worker);

#endif
