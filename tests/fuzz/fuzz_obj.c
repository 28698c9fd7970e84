/* fuzz_obj.c - libFuzzer target for the OBJ reader (no material libraries: the fuzzer
 * must not open files). An accepted mesh must also survive conversion to NFF.
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "../io/io_test_util.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[256];
    vw_scene *s = NULL;
    vw_status st = vw_scene_read_obj("fuzz.obj", (const char *)data, size, NULL, &s, err,
                                     sizeof err);
    if (st != VW_OK) {
        if (s || (st != VW_E_INPUT && st != VW_E_NOMEM && st != VW_E_LIMIT))
            abort();
        return 0;
    }
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    for (size_t i = 0; i < s->nindices; i++)
        if (s->indices[i] < 0 || (size_t)s->indices[i] >= s->nvertices)
            abort();
    size_t n = 0;
    char *text = nff_string(s, &n);
    vw_scene *back = NULL;
    if (!text || vw_scene_read_nff("obj.nff", text, n, &back, err, sizeof err) != VW_OK) {
        fprintf(stderr, "converted mesh does not read back: %s\n", err);
        abort();
    }
    free(text);
    vw_scene_free(back);
    vw_scene_free(s);
    return 0;
}
