/* hello_module.h - the tutorial's module (docs/tutorial.md): every cell counts the points
 * it owns and tells its face neighbours; the output process collects, per cell, its own
 * count and the sum of its neighbours' counts.
 */
#ifndef EX_HELLO_MODULE_H
#define EX_HELLO_MODULE_H

#include <stddef.h>
#include <stdint.h>
#include <vwalls/vwalls.h>

/* The object: a point. Objects are plain records, copied into cells (and processes). */
typedef struct ex_point {
    double p[3];
} ex_point;

/* What the output process collects: one entry per cell. */
typedef struct ex_hello_result {
    int ncells;
    int64_t *own;         /* points owned by the cell */
    int64_t *neighbours;  /* points owned by its face neighbours, summed */
    int64_t summaries;    /* summaries received: one per cell, when all goes well */
} ex_hello_result;

/* The module's counters, summed over cells and processes after a run. */
enum { EX_HELLO_CNT_POINTS, EX_HELLO_CNT_MESSAGES, EX_HELLO_NCOUNTERS };

/* The module itself; its user pointer (vw_world_create) must be an ex_hello_result. */
extern const vw_module ex_hello_module;

#endif
