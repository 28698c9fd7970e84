/* example_opts.h - the options the two example subcommands share (random spheres in
 * the unit cube, a grid of cells, workers, stats, --check, --quiet), parsed once.
 */
#ifndef VW_TOOLS_EXAMPLE_OPTS_H
#define VW_TOOLS_EXAMPLE_OPTS_H

#include "vwalls/vwalls.h"

typedef struct vw_example_opts {
    long spheres, seed, workers;
    double radius;
    int dims[3];
    int check, quiet;
    const char *stats;
} vw_example_opts;

/* Parses argv[1..argc) into o, whose fields hold the defaults on entry. Returns -1 to
   go on, or the exit status to return at once (after --help, a bad option, or a
   --stats that cannot be written: vw_cli_check_outputs, collective under MPI). */
int vw_example_opts_parse(const char *cmd, int argc, char **argv, vw_example_opts *o,
                          void (*help)(void));

/* The spheres (o->spheres of them, *s, malloc'ed) and the grid of cells (*d) every
   process makes itself, agreed on before the world is made: one process out of memory
   alone would leave the others waiting for it there. others_ok: the command's own
   allocations for the spheres succeeded. Returns the agreed exit status (vw_cli_agree);
   on failure *s and *d are NULL. */
struct ex_sphere;
int vw_example_spheres(const char *cmd, const vw_example_opts *o, int others_ok,
                       struct ex_sphere **s, vw_decomp **d);

#endif
