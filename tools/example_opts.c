/* example_opts.c - parsing of the options the example subcommands share. */
#include "example_opts.h"

#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "pairs.h"

int vw_example_spheres(const char *cmd, const vw_example_opts *o, int others_ok, ex_sphere **s,
                       vw_decomp **d)
{
    char err[256] = "";
    int rc = VW_EXIT_OK;
    long n = o->spheres;
    *d = NULL;
    *s = vw_cli_fault("spheres-nomem") ? NULL : malloc(sizeof **s * (size_t)(n ? n : 1));
    if (!*s || !others_ok)
        rc = vw_cli_fail(cmd, VW_EXIT_FAIL, err, sizeof err, "out of memory for %ld spheres", n);
    if (*s) ex_pairs_generate(*s, (size_t)n, o->radius, (uint64_t)o->seed);
    vw_box unit = {{0, 0, 0}, {1, 1, 1}};
    vw_status st = rc == VW_EXIT_OK ? vw_decomp_create_grid(&unit, o->dims, d) : VW_OK;
    if (st != VW_OK)
        rc = vw_cli_fail(cmd, VW_EXIT_FAIL, err, sizeof err, "cannot make the decomposition: %s",
                         vw_status_message(st));
    if ((rc = vw_cli_agree(cmd, rc, err, sizeof err)) != VW_EXIT_OK) {
        vw_decomp_free(*d);
        free(*s);
        *d = NULL;
        *s = NULL;
    }
    return rc;
}

int vw_example_opts_parse(const char *cmd, int argc, char **argv, vw_example_opts *o,
                          void (*help)(void))
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return VW_EXIT_OK;
        } else if (!strcmp(a, "--check")) {
            o->check = 1;
        } else if (!strcmp(a, "--quiet")) {
            o->quiet = 1;
        } else if (!strcmp(a, "--spheres")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_int(cmd, a, v, 0, 100000000, &o->spheres))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--seed")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_int(cmd, a, v, 0, 0x7fffffffL, &o->seed))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--workers")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_int(cmd, a, v, 1, 1024, &o->workers))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--radius")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) ||
                vw_cli_double(cmd, a, v, 1e-6, 0.25, &o->radius))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--cells")) {
            if (!(v = vw_cli_value(cmd, argc, argv, &i)) || vw_cli_layout(cmd, a, v, o->dims))
                return VW_EXIT_USAGE;
        } else if (!strcmp(a, "--stats")) {
            if (!(o->stats = vw_cli_output(cmd, argc, argv, &i))) return VW_EXIT_USAGE;
        } else if (a[0] == '-' && a[1]) {
            vw_cli_error(cmd, "unknown option '%s' (try --help)", a);
            return VW_EXIT_USAGE;
        } else { /* the spheres are generated: there is no scene to give */
            vw_cli_error(cmd, "unexpected argument '%s': takes options only (try --help)", a);
            return VW_EXIT_USAGE;
        }
    }
    /* Before the work: a --stats into a missing directory failed after the result was
       printed. */
    const char *opts[] = {"--stats"}, *paths[] = {o->stats};
    int rc = vw_cli_check_outputs(cmd, opts, paths, 1);
    return rc == VW_EXIT_OK ? -1 : rc;
}
