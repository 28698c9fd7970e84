/* replay.c - runs a fuzz target's LLVMFuzzerTestOneInput on files, without libFuzzer:
 * the targets' properties then hold in every ordinary build and under the sanitizers
 * (ctest fuzz_replay_*), on the repository's good and bad scenes and the fuzzers'
 * findings. A property that fails aborts, which fails the test.
 * Usage: replay FILE...
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++) {
        FILE *f = fopen(argv[i], "rb");
        if (!f) {
            fprintf(stderr, "%s: cannot open\n", argv[i]);
            return 1;
        }
        size_t cap = 1 << 16, n = 0;
        uint8_t *buf = malloc(cap);
        for (;;) {
            if (!buf) {
                fprintf(stderr, "%s: out of memory\n", argv[i]);
                return 1;
            }
            n += fread(buf + n, 1, cap - n, f);
            if (n < cap) break;
            uint8_t *grown = realloc(buf, cap *= 2);
            if (!grown) free(buf);
            buf = grown;
        }
        fclose(f);
        printf("%s (%zu bytes)\n", argv[i], n);
        LLVMFuzzerTestOneInput(buf, n);
        free(buf);
    }
    return 0;
}
