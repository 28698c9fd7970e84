/* components.h - the second example module: connected components of touching spheres,
 * distributed. Labels travel across walls until they stop changing. Read pairs.c first;
 * this one reuses its spheres and adds iteration to quiescence and output messages.
 */
#ifndef VW_EXAMPLE_COMPONENTS_H
#define VW_EXAMPLE_COMPONENTS_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/vwalls.h"
#include "pairs.h"

/* The sequential reference: labels[i] = the smallest id in sphere i's component (spheres
   are connected when they touch, transitively). O(n^2). Returns the number of components. */
int64_t ex_components_reference(const ex_sphere *s, size_t n, int64_t *labels);

/* The distributed labelling on decomposition d, with the same meaning of labels. Sphere
   ids must be 0..n-1 and every radius at most rmax (ex_spheres_check, pairs.h; else
   VW_E_INVAL before any world is made, ex_errmsg saying why). labels (n entries) is
   filled on the output process only; *ncomponents is valid on every process. If
   out_world is not NULL the world is handed back (for stats, and the counters below),
   else freed. */
vw_status ex_components_label(const ex_sphere *s, size_t n, double rmax, const vw_decomp *d,
                              const vw_config *cfg, int64_t *labels, int64_t *ncomponents,
                              vw_world **out_world);

/* The module's counters, for vw_world_counter() on a world handed back. */
enum {
    EX_COMPONENTS_CNT_COMPONENTS,   /* spheres whose label is their own id */
    EX_COMPONENTS_CNT_LOCAL,        /* components inside cells before any exchange */
    EX_COMPONENTS_CNT_LABEL_MSGS,   /* label messages sent across walls */
    EX_COMPONENTS_CNT_RELABELS,     /* times a local component's label went down */
    EX_COMPONENTS_NCOUNTERS
};

#endif
