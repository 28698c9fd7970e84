/* sphere_bins.h - what both example modules share: the meaning of "touching", the cells
 * a sphere must be sent to, and the neighbour search: a cell's own spheres sorted by the
 * key of a grid bin at least 2*rmax wide, so that the spheres touching a query sphere are
 * found in O(log n) whatever the layout of cells.
 */
#ifndef VW_EXAMPLE_SPHERE_BINS_H
#define VW_EXAMPLE_SPHERE_BINS_H

#include <math.h>
#include <stdlib.h>

#include "pairs.h"

/* The two modules' entry points, ex_pairs_count and ex_components_label, begin and end
   alike; pairs.c keeps ex_errmsg's message (pairs.h). ex__spheres_agree: the spheres
   checked (ex_spheres_check, its reason becoming the message) and the verdict agreed on
   before the world is made (vw_config_agree). ex__world_failed: st returned, and when it
   is not VW_OK the message becomes vw_world_errmsg(w) (w NULL: why vw_world_create
   failed), taken before the world is freed. */
vw_status ex__spheres_agree(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                            int ids_are_indices, const vw_config *cfg);
vw_status ex__world_failed(vw_status st, const vw_world *w);

typedef struct ex_bins {
    ex_sphere *own;   /* spheres whose centre lies in this cell, sorted by key */
    uint64_t *key;
    size_t n;
    double h, lo[3];  /* bin width and the grid's origin (the world box's low corner) */
} ex_bins;

/* Touching, as pairs.h defines it: |a - b|^2 <= (ra + rb)^2, evaluated in double exactly
   so. It is symmetric bit for bit (the differences only change sign), so every cell,
   whatever the layout, decides a pair alike. */
static inline int ex_touching(const ex_sphere *a, const ex_sphere *b)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (a->c[k] - b->c[k]) * (a->c[k] - b->c[k]);
    return d2 <= (a->r + b->r) * (a->r + b->r);
}

/* The cells that may own the centre of a sphere touching s (any radius up to rmax): those
   whose box overlaps s's box widened by rmax. That box's ends are rounded: a sphere
   exactly touching s with its centre on a wall could lie an ulp beyond them, and the cell
   across the wall would never hear of s (the pair then counted on one layout and not on
   another). So the box is padded by far more than rounding (1e-12 of the coordinates'
   size): a cell too many costs a message, never a wrong result, as every receiver tests
   touching itself. Returns the number of cells (self included), ids in cells[0..max). */
static inline int ex_reach_cells(const vw_decomp *d, const ex_sphere *s, double rmax, int *cells,
                                 int max)
{
    vw_box reach, world = vw_decomp_world(d);
    double size = s->r + rmax;
    for (int k = 0; k < 3; k++) {
        reach.lo[k] = s->c[k] - s->r - rmax;
        reach.hi[k] = s->c[k] + s->r + rmax;
        size += fabs(s->c[k]) + fabs(world.lo[k]) + fabs(world.hi[k]);
    }
    return vw_decomp_cells_overlapping(d, &reach, 1e-12 * size, cells, max);
}

/* Bins: indices 0 .. EX_BIN_MAX per axis, 21 bits each in a 64-bit key, z fastest, so the
   bins (x, y, z-1..z+1) are one run of the sorted keys. Index = floor((c - lo) / h),
   clamped: clamping keeps the order of indices and never moves two of them further apart,
   so spheres in adjacent bins stay in adjacent (or the same) bins. */
#define EX_BIN_MAX ((int64_t)(1 << 21) - 1)

static inline int64_t ex_bin_clamp(double t)
{
    return !(t >= 0) ? 0 : t >= (double)EX_BIN_MAX ? EX_BIN_MAX : (int64_t)t;
}

static inline int64_t ex_bin_index(const ex_bins *b, const double c[3], int a)
{
    return ex_bin_clamp(floor((c[a] - b->lo[a]) / b->h));
}

static inline uint64_t ex_bin_key(int64_t x, int64_t y, int64_t z)
{
    return (uint64_t)x << 42 | (uint64_t)y << 21 | (uint64_t)z;
}

static inline int ex_bins_cmp(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Keeps the spheres of s[0..n) whose centre the cell owns (a centre on a wall goes to
   the + side; near a wall a centre is placed in two cells, so this choice matters).
   Bins are 2*rmax wide and a hair more (touching in double may exceed 2*rmax by a few
   ulps: the hair keeps such a pair in adjacent bins), and at least 2^-20 of the world's
   extent, so the indices of centres in the world fit their 21 bits (and rmax 0 is no
   division by 0). */
static inline vw_status ex_bins_build(ex_bins *b, vw_ctx *ctx, const ex_sphere *s, size_t n,
                                      double rmax)
{
    static const double dir[3] = {1, 1, 1};
    const vw_decomp *d = vw_ctx_decomp(ctx);
    vw_box world = vw_decomp_world(d);
    double extent = 0;
    for (int k = 0; k < 3; k++) {
        b->lo[k] = world.lo[k];
        if (world.hi[k] - world.lo[k] > extent) extent = world.hi[k] - world.lo[k];
    }
    b->h = fmax(2 * rmax * (1 + 1e-9), extent * 0x1p-20);
    if (!(b->h > 0)) b->h = 1;
    uint64_t (*tmp)[2] = malloc(sizeof *tmp * (n ? n : 1)); /* (key, index) to sort */
    b->own = malloc(sizeof *b->own * (n ? n : 1));
    b->key = malloc(sizeof *b->key * (n ? n : 1));
    b->n = 0;
    if (!tmp || !b->own || !b->key) {
        free(tmp), free(b->own), free(b->key);
        b->own = NULL, b->key = NULL;
        return VW_E_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        if (vw_decomp_locate(d, s[i].c, dir) == vw_ctx_cell(ctx)) {
            tmp[b->n][0] = ex_bin_key(ex_bin_index(b, s[i].c, 0), ex_bin_index(b, s[i].c, 1),
                                      ex_bin_index(b, s[i].c, 2));
            tmp[b->n++][1] = i;
        }
    qsort(tmp, b->n, sizeof *tmp, ex_bins_cmp);
    for (size_t i = 0; i < b->n; i++) b->key[i] = tmp[i][0], b->own[i] = s[tmp[i][1]];
    free(tmp);
    return VW_OK;
}

static inline void ex_bins_free(ex_bins *b)
{
    free(b->own);
    free(b->key);
}

static inline size_t ex_bins_lower_bound(const ex_bins *b, uint64_t key)
{
    size_t lo = 0, hi = b->n;
    while (lo < hi) {
        size_t mid = (lo + hi) / 2;
        if (b->key[mid] < key) lo = mid + 1; else hi = mid;
    }
    return lo;
}

/* Calls fn(j, arg) once for every own sphere j that touches q. The bins visited are
   distinct, so no sphere is visited twice, even where clamping merged bins. */
static inline void ex_bins_for_touching(const ex_bins *b, const ex_sphere *q,
                                        void (*fn)(size_t j, void *arg), void *arg)
{
    int64_t lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        int64_t i = ex_bin_index(b, q->c, a);
        lo[a] = i > 0 ? i - 1 : 0;
        hi[a] = i < EX_BIN_MAX ? i + 1 : EX_BIN_MAX;
    }
    for (int64_t x = lo[0]; x <= hi[0]; x++)
        for (int64_t y = lo[1]; y <= hi[1]; y++) {
            uint64_t last = ex_bin_key(x, y, hi[2]);
            for (size_t j = ex_bins_lower_bound(b, ex_bin_key(x, y, lo[2]));
                 j < b->n && b->key[j] <= last; j++)
                if (ex_touching(&b->own[j], q)) fn(j, arg);
        }
}

#endif
