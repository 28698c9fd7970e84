/* sphere_bins.h - the neighbour search both example modules use: a cell's own spheres
 * sorted by the key of a grid bin of spacing h = 2*rmax, so that the spheres touching
 * a query sphere are found in O(log n) whatever the layout of cells.
 */
#ifndef VW_EXAMPLE_SPHERE_BINS_H
#define VW_EXAMPLE_SPHERE_BINS_H

#include <math.h>
#include <stdlib.h>

#include "pairs.h"

typedef struct ex_bins {
    ex_sphere *own;   /* spheres whose centre lies in this cell, sorted by key */
    uint64_t *key;
    size_t n;
    double h;
} ex_bins;

static inline int ex_touching(const ex_sphere *a, const ex_sphere *b)
{
    double d2 = 0;
    for (int k = 0; k < 3; k++) d2 += (a->c[k] - b->c[k]) * (a->c[k] - b->c[k]);
    return d2 <= (a->r + b->r) * (a->r + b->r);
}

/* Two touching spheres lie in adjacent bins. Keys order bins with z fastest, so the
   bins (x+dx, y+dy, z-1..z+1) are one run of the sorted array. */
static inline uint64_t ex_bin_key(const double c[3], double h, int dx, int dy, int dz)
{
    uint64_t k = 0;
    for (int a = 0; a < 3; a++) {
        int64_t i = (int64_t)floor(c[a] / h) + 1 + (a == 0 ? dx : a == 1 ? dy : dz);
        k = (k << 21) | (uint64_t)(i < 0 ? 0 : i);
    }
    return k;
}

static inline int ex_bins_cmp(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Keeps the spheres of s[0..n) whose centre the cell owns (a centre on a wall goes to
   the + side; near a wall a centre is placed in two cells, so this choice matters). */
static inline vw_status ex_bins_build(ex_bins *b, vw_ctx *ctx, const ex_sphere *s, size_t n,
                                      double h)
{
    static const double dir[3] = {1, 1, 1};
    uint64_t (*tmp)[2] = malloc(sizeof *tmp * (n ? n : 1)); /* (key, index) to sort */
    b->own = malloc(sizeof *b->own * (n ? n : 1));
    b->key = malloc(sizeof *b->key * (n ? n : 1));
    b->n = 0;
    b->h = h;
    if (!tmp || !b->own || !b->key) {
        free(tmp), free(b->own), free(b->key);
        b->own = NULL, b->key = NULL;
        return VW_E_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        if (vw_decomp_locate(vw_ctx_decomp(ctx), s[i].c, dir) == vw_ctx_cell(ctx))
            tmp[b->n][0] = ex_bin_key(s[i].c, h, 0, 0, 0), tmp[b->n++][1] = i;
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

/* Calls fn(j, arg) for every own sphere j that touches q. */
static inline void ex_bins_for_touching(const ex_bins *b, const ex_sphere *q,
                                        void (*fn)(size_t j, void *arg), void *arg)
{
    for (int dx = -1; dx <= 1; dx++)
        for (int dy = -1; dy <= 1; dy++) {
            uint64_t last = ex_bin_key(q->c, b->h, dx, dy, 1);
            for (size_t j = ex_bins_lower_bound(b, ex_bin_key(q->c, b->h, dx, dy, -1));
                 j < b->n && b->key[j] <= last; j++)
                if (ex_touching(&b->own[j], q)) fn(j, arg);
        }
}

#endif
