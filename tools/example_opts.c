/* example_opts.c - parsing of the options the example subcommands share. */
#include "example_opts.h"

#include <string.h>

#include "cli.h"

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
    return -1;
}
