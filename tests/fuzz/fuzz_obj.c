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

/* Most inputs hold a word the OBJ format does not define, which the reader warns about
   once per file: not a finding, and the warnings would bury the fuzzer's own output. */
static void quiet(const char *msg, void *user)
{
    (void)msg, (void)user;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[256];
    vw_scene_set_warning_handler(quiet, NULL);
    vw_scene *s = NULL;
    vw_status st = vw_scene_read_obj("fuzz.obj", (const char *)data, size, NULL, &s, err,
                                     sizeof err);
    fuzz_check_mesh(st, s);
    return 0;
}
