/* fuzz_ply.c - libFuzzer target for the PLY reader (ASCII and binary). An accepted mesh
 * must index only its own vertices, and survive conversion to NFF.
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
    vw_status st = vw_scene_read_ply("fuzz.ply", data, size, &s, err, sizeof err);
    fuzz_check_mesh(st, s);
    return 0;
}
