/* examples_main.c - a user's program built out of tree against the installed vwalls:
 * runs both example modules (pairs, components) on a few layouts and compares them with
 * their sequential references; checks that headers and library report the same version.
 *   usage: examples_main EXPECTED_VERSION
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "components.h"
#include "pairs.h"

int main(int argc, char **argv)
{
    if (strcmp(vw_version(), VW_VERSION_STRING) || (argc > 1 && strcmp(argv[1], vw_version()))) {
        fprintf(stderr, "version: library %s, headers %s, expected %s\n", vw_version(),
                VW_VERSION_STRING, argc > 1 ? argv[1] : "-");
        return 1;
    }
    enum { N = 2000 };
    const double rmax = 0.06;
    ex_sphere *s = malloc(sizeof *s * N);
    int64_t *labels = malloc(sizeof *labels * N), *ref = malloc(sizeof *ref * N);
    if (!s || !labels || !ref) return 1;
    ex_pairs_generate(s, N, rmax, 3);
    int64_t ref_pairs = ex_pairs_brute(s, N), ref_comp = ex_components_reference(s, N, ref);
    static const int layouts[3][3] = {{1, 1, 1}, {2, 4, 1}, {2, 2, 2}};
    vw_box unit = {{0, 0, 0}, {1, 1, 1}};
    int rc = 0;
    for (int l = 0; l < 3; l++) {
        vw_decomp *d;
        if (vw_decomp_create_grid(&unit, layouts[l], &d) != VW_OK) return 1;
        vw_config cfg;
        vw_config_init(&cfg);
        cfg.workers = 2;
        int64_t pairs = -1, ncomp = -1;
        vw_status st = ex_pairs_count(s, N, rmax, d, &cfg, &pairs, NULL);
        if (st == VW_OK) st = ex_components_label(s, N, rmax, d, &cfg, labels, &ncomp, NULL);
        int same = st == VW_OK && pairs == ref_pairs && ncomp == ref_comp &&
                   !memcmp(labels, ref, sizeof *ref * N);
        printf("%d cells: pairs %lld (%lld), components %lld (%lld): %s\n",
               vw_decomp_cell_count(d), (long long)pairs, (long long)ref_pairs, (long long)ncomp,
               (long long)ref_comp, same ? "ok" : "MISMATCH");
        rc |= !same;
        vw_decomp_free(d);
    }
    free(s), free(labels), free(ref);
    return rc;
}
