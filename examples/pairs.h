/* pairs.h - the example module: distributed counting of touching sphere pairs.
 * Read pairs.c first: it is the smallest complete vwalls module.
 *
 * Two spheres touch when the distance of their centres is at most the sum of their
 * radii, evaluated in double as |a - b|^2 <= (ra + rb)^2 (ex_touching in sphere_bins.h):
 * overlapping spheres touch, and so do spheres exactly tangent, a sphere of radius 0 on
 * another's surface, and two equal spheres. Every cell decides every pair by that same
 * expression, so the count is the brute force's on every layout and worker count.
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

/* n spheres with centres uniform in the unit cube, radii in [rmax/4, rmax], ids 0..n-1. */
void ex_pairs_generate(ex_sphere *s, size_t n, double rmax, uint64_t seed);
/* The O(n^2) reference. */
int64_t ex_pairs_brute(const ex_sphere *s, size_t n);

/* What both example modules need of their spheres: rmax finite and not negative; every
   radius from 0 to rmax (the reach of a ghost); every centre in d's world box (a centre
   outside is in no cell, and its pairs would be lost); ids distinct (a pair split by a
   wall is counted by the sphere of smaller id), and 0..n-1 when ids_are_indices.
   VW_E_INVAL, with the first offence in why (len bytes; why may be NULL; of ids given
   twice, the smallest), otherwise; "" in why when they pass. */
vw_status ex_spheres_check(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                           int ids_are_indices, char *why, size_t len);

/* The distributed count: one run of the module on decomposition d. If out_world is
   not NULL the world is handed back (for stats), else freed. Spheres ex_spheres_check
   refuses are VW_E_INVAL, before any world is made (*out_world NULL); ex_errmsg says
   why. */
vw_status ex_pairs_count(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                         const vw_config *cfg, int64_t *pairs, vw_world **out_world);

/* Why this thread's last ex_pairs_count or ex_components_label (components.h) failed,
   "no error" when it did not; read it before the next call, which clears it. Spheres
   refused: ex_spheres_check's own words (agreed under MPI, vw_config_agree: "rank R: "
   in front, the same on every process). A world not made, or a step of its life that
   failed: vw_world_errmsg's, kept after the world is freed. As vw_world_errmsg(NULL)
   is for vw_world_create, this is for calls that may leave no world to ask. */
const char *ex_errmsg(void);

/* The module's counters, for vw_world_counter() on a world handed back. */
enum {
    EX_PAIRS_CNT_PAIRS,     /* touching pairs (the result) */
    EX_PAIRS_CNT_GHOSTS,    /* ghosts sent to other cells */
    EX_PAIRS_NCOUNTERS
};

#endif
