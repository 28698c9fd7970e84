/* vw_test.h - the few assertion macros every test executable uses: on failure they
 * print the expression, both values, file and line, and exit non-zero (ctest reads
 * the status); EXPECT records the failure and goes on.
 */
#ifndef VW_TEST_H
#define VW_TEST_H

#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int vw_test_checks;

/* splitmix64: a well-mixed 64-bit function of z (z plus the golden ratio, then two
   multiply-xorshift rounds), for tests that derive their data from a seed. */
static inline uint64_t vw_test_mix(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

#define CHECK(cond)                                                                     \
    do {                                                                                \
        vw_test_checks++;                                                               \
        if (!(cond)) {                                                                  \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);     \
            exit(1);                                                                    \
        }                                                                               \
    } while (0)

#define CHECK_EQ_INT(a, b)                                                              \
    do {                                                                                \
        vw_test_checks++;                                                               \
        long long va_ = (long long)(a), vb_ = (long long)(b);                           \
        if (va_ != vb_) {                                                               \
            fprintf(stderr, "%s:%d: %s == %s failed: %lld != %lld\n", __FILE__, __LINE__, \
                    #a, #b, va_, vb_);                                                  \
            exit(1);                                                                    \
        }                                                                               \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                           \
    do {                                                                                \
        vw_test_checks++;                                                               \
        double va_ = (double)(a), vb_ = (double)(b);                                    \
        if (!(fabs(va_ - vb_) <= (tol))) {                                              \
            fprintf(stderr, "%s:%d: |%s - %s| <= %s failed: %.17g vs %.17g\n", __FILE__, \
                    __LINE__, #a, #b, #tol, va_, vb_);                                  \
            exit(1);                                                                    \
        }                                                                               \
    } while (0)

/* Like CHECK, but goes on after a failure (counted in vw_test_failures; the test ends
   with that count's verdict) and prints a printf-style message with the expression. */
static int vw_test_failures __attribute__((unused));
#define EXPECT(cond, ...)                                                               \
    do {                                                                                \
        vw_test_checks++;                                                               \
        if (!(cond)) {                                                                  \
            fprintf(stderr, "%s:%d: check failed: %s: ", __FILE__, __LINE__, #cond);     \
            fprintf(stderr, __VA_ARGS__);                                               \
            fputc('\n', stderr);                                                        \
            vw_test_failures++;                                                         \
        }                                                                               \
    } while (0)

#define TEST_DONE()                                                                     \
    do {                                                                                \
        if (vw_test_failures) {                                                         \
            printf("%d checks, %d failed\n", vw_test_checks, vw_test_failures);         \
            return 1;                                                                   \
        }                                                                               \
        printf("%d checks passed\n", vw_test_checks);                                   \
        return 0;                                                                       \
    } while (0)

/* The n bytes of text t with every LF made CR (crlf 0: classic Mac OS) or CRLF (crlf 1:
   Windows), NUL-terminated, malloc'ed; its length in *out_n (may be NULL). For the
   readers' tests: every line end reads alike. */
static char *vw_test_line_ends(const char *t, size_t n, int crlf, size_t *out_n)
    __attribute__((unused));
static char *vw_test_line_ends(const char *t, size_t n, int crlf, size_t *out_n)
{
    char *o = malloc(2 * n + 1);
    size_t k = 0;
    CHECK(o != NULL);
    for (size_t i = 0; i < n; i++) {
        if (t[i] == '\n') {
            o[k++] = '\r';
            if (!crlf) continue;
        }
        o[k++] = t[i];
    }
    o[k] = '\0';
    if (out_n) *out_n = k;
    return o;
}

#endif
