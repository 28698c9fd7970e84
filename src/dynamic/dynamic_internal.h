/* dynamic_internal.h - what the files of the dynamic-scene handler share.
 */
#ifndef VW_DYNAMIC_INTERNAL_H
#define VW_DYNAMIC_INTERNAL_H

#include "vwalls/dynamic.h"
#include "vwalls/engine.h"

/* The test of one probe against one obstacle shape, as a cell runs it: VW_PROBE_END
   and/or one of VW_PROBE_SWEEP, VW_PROBE_START and VW_PROBE_THROUGH (dynamic.h), 0 for
   no hit. The brute-force reference uses it too, so both decide by one rule. */
int vw__probe_test(const vw_probe *p, const vw_shape *o, double tol);

/* Whether a, swept by d, comes nearer to b along its path than it is at its start, by
   more than tol (pairs with a sphere; 0 for the others): a mover that starts sunk in b
   and goes deeper (through it) is THROUGH, not START, for the sweep (shape.c). */
int vw__shape_sweep_deepens(const vw_shape *a, const double d[3], const vw_shape *b, double tol);

#endif
