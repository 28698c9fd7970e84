/* example_opts.h - the options the two example subcommands share (random spheres in
 * the unit cube, a grid of cells, workers, stats, --check, --quiet), parsed once.
 */
#ifndef VW_TOOLS_EXAMPLE_OPTS_H
#define VW_TOOLS_EXAMPLE_OPTS_H

typedef struct vw_example_opts {
    long spheres, seed, workers;
    double radius;
    int dims[3];
    int check, quiet;
    const char *stats;
} vw_example_opts;

/* Parses argv[1..argc) into o, whose fields hold the defaults on entry. Returns -1 to
   go on, or the exit status to return at once (after --help, or a bad option). */
int vw_example_opts_parse(const char *cmd, int argc, char **argv, vw_example_opts *o,
                          void (*help)(void));

#endif
