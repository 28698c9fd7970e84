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
    fuzz_check_mesh(st, s);
    return 0;
}
