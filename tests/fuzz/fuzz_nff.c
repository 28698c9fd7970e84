/* fuzz_nff.c - libFuzzer target for the NFF reader. Besides "never crash", it checks
 * a property: any scene the reader accepts is written and read back to the same
 * scene, bit for bit.
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
    vw_status st = vw_scene_read_nff("fuzz.nff", (const char *)data, size, &s, err, sizeof err);
    if (st != VW_OK) {
        if (s || (st != VW_E_INPUT && st != VW_E_NOMEM && st != VW_E_LIMIT))
            abort();
        return 0;
    }
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    size_t n = 0;
    char *text = nff_string(s, &n);
    if (!text)
        abort();
    vw_scene *back = NULL;
    if (vw_scene_read_nff("again.nff", text, n, &back, err, sizeof err) != VW_OK) {
        fprintf(stderr, "written scene does not read back: %s\n", err);
        abort();
    }
    if (!scene_equal(s, back))
        abort();
    free(text);
    vw_scene_free(back);
    vw_scene_free(s);
    return 0;
}
