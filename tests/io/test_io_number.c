/* test_io_number.c - vw__parse_double, the scene readers' number parser, must read
 * every token exactly as strtod does (same bits, same sign of zero, same verdict on
 * what is not a number), except that it takes decimal notation only: a hexadecimal
 * float or white space first is not a number (strtod reads both): random doubles printed with 6 to 20 digits, random decimal
 * strings with up to 25 digits and exponents far beyond the fast path's, and numbers
 * that lie exactly halfway between two doubles (where rounding twice would go wrong).
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"
#include "vw_test.h"

static uint64_t rng = 0x9e3779b97f4a7c15ull;
static uint64_t next(void)
{
    rng ^= rng << 13, rng ^= rng >> 7, rng ^= rng << 17;
    return rng;
}

static long long checked;

/* vw__parse_double against strtod on the whole token s. */
static void same(const char *s)
{
    size_t n = strlen(s);
    double got = 0, want = 0;
    int r = vw__parse_double(s, n, &got);
    char *end;
    want = strtod(s, &end);
    int hex = strpbrk(s, "xX") != NULL, space = n && (*s == ' ' || *s == '\t');
    int want_r = (end != s + n || n == 0 || hex || space) ? 0 : !isfinite(want) ? -1 : 1;
    checked++;
    EXPECT(r == want_r, "'%s': verdict %d, strtod says %d", s, r, want_r);
    if (r == 1 && want_r == 1)
        EXPECT(memcmp(&got, &want, sizeof got) == 0, "'%s': %.17g, strtod %.17g", s, got, want);
}

int main(void)
{
    static const char *const fixed[] = {
        "0", "-0", "0.0", "-0.000", "1", "-1", "+1", ".5", "5.", "-.5", ".", "-", "+", "",
        "1e", "1e+", "1e-", "e5", "1e5", "1E5", "1e+05", "1.5e-3", "0x10", "0x1p3", "inf",
        "-inf", "nan", "NaN", "infinity", "1e309", "-1e309", "1e-400", "1..2", "1.2.3",
        "1e5e5", "--1", "1-", " 1", "1 ", "-0x10", "+0X1p3", "0x", "+inf", "+-1", "-+1", "+.5", "0.1", "0.2", "0.3", "2.1000000000000001",
        "0.66666666666666663", "0.57735025882720947", "9007199254740993",
        "9007199254740992", "9007199254740995", "18014398509481987", "123456789012345678",
        "1234567890123456789", "12345678901234567890", "9999999999999999999",
        "99999999999999999999", "1e27", "1e-27", "1e28", "1e-28", "4.9406564584124654e-324",
        "2.2250738585072014e-308", "1.7976931348623157e308", "0.000000000000000000000000001",
        "100000000000000000000000000000", "1e0000", "1e00001", "00000000000000000000001.5",
        "1.00000000000000000000000", "3.0827000141143799", "0.80000001192092896"};
    for (size_t i = 0; i < sizeof fixed / sizeof *fixed; i++) same(fixed[i]);

    /* Longer than 127 bytes: not a number, fast path or not. */
    {
        char longnum[200];
        memset(longnum, '0', sizeof longnum);
        longnum[198] = '1';
        longnum[199] = '\0';
        double v = 0;
        CHECK_EQ_INT(vw__parse_double(longnum, 199, &v), 0);
        CHECK_EQ_INT(vw__parse_double(longnum + 72, 127, &v), 1);
        CHECK(v == 1.0);
    }

    char buf[96];
    /* Random doubles of every magnitude the fast path covers and beyond, printed with
       6 to 20 significant digits. */
    for (int k = 0; k < 300000; k++) {
        double m = (double)(next() >> 11) / 9007199254740992.0;
        int e = (int)(next() % 80) - 40;
        double x = m * pow(10.0, e) * (next() & 1 ? -1 : 1);
        int digits = 6 + (int)(next() % 15);
        snprintf(buf, sizeof buf, next() & 1 ? "%.*g" : "%.*e", digits, x);
        same(buf);
    }
    /* Random decimal strings: up to 25 digits, a point anywhere, exponents to +-40. */
    for (int k = 0; k < 300000; k++) {
        int nd = 1 + (int)(next() % 25), point = (int)(next() % (unsigned)(nd + 1)), o = 0;
        if (next() & 1) buf[o++] = '-';
        for (int i = 0; i < nd; i++) {
            if (i == point && (next() & 1)) buf[o++] = '.';
            buf[o++] = (char)('0' + next() % 10);
        }
        if (next() % 3 == 0) o += snprintf(buf + o, sizeof buf - (size_t)o, "e%d", (int)(next() % 81) - 40);
        buf[o] = '\0';
        same(buf);
    }
    /* Exact halfway points: (2m + 1) * 2^(e - 1) for a 53-bit m, written out exactly in
       decimal where that takes at most 19 digits (small e), so the fast path sees them. */
    for (int k = 0; k < 20000; k++) {
        uint64_t m = (1ull << 52) | (next() >> 12);
        int e = -(int)(next() % 12);
        /* (2m + 1) / 2^(1 - e) = (2m + 1) * 5^(1 - e) / 10^(1 - e) */
        unsigned __int128 v = 2 * (unsigned __int128)m + 1;
        for (int i = 0; i < 1 - e; i++) v *= 5;
        char digits[64];
        int nd = 0;
        while (v) {
            digits[nd++] = (char)('0' + (int)(v % 10));
            v /= 10;
        }
        int o = 0;
        for (int i = nd - 1; i >= 0; i--) buf[o++] = digits[i];
        snprintf(buf + o, sizeof buf - (size_t)o, "e-%d", 1 - e);
        same(buf);
        /* and the integer midpoints above 2^53 */
        snprintf(buf, sizeof buf, "%llu", (unsigned long long)((m << 1) + 1) << (next() % 10));
        same(buf);
    }
    printf("%lld numbers read as strtod reads them, %d failures\n", checked, vw_test_failures);
    return vw_test_failures ? 1 : 0;
}
