/* pairs.h - the example module: distributed counting of touching sphere pairs.
 * Read pairs.c first: it is the smallest complete vwalls module.
 */
#ifndef VW_EXAMPLE_PAIRS_H
#define VW_EXAMPLE_PAIRS_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/vwalls.h"

typedef struct ex_sphere {
    int64_t id;
    double c[3], r;
} ex_sphere;

/* n spheres with centres uniform in the unit cube and radii in (0, rmax]. */
void ex_pairs_generate(ex_sphere *s, size_t n, double rmax, uint64_t seed);
/* The O(n^2) reference. */
int64_t ex_pairs_brute(const ex_sphere *s, size_t n);
/* The distributed count: one run of the module on decomposition d. If out_world is
   not NULL the world is handed back (for stats), else freed. */
vw_status ex_pairs_count(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                         const vw_config *cfg, int64_t *pairs, vw_world **out_world);

#endif
