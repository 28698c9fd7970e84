/* decimal.c - vw_strtod_decimal: strtod restricted to decimal notation. */
#include <errno.h>
#include <stdlib.h>
#include "vwalls/common.h"

double vw_strtod_decimal(const char *s, char **end, int plus)
{
    const char *p = s;
    if (*p == '-' || (plus && *p == '+')) p++;
    int digit = (*p >= '0' && *p <= '9') || (*p == '.' && p[1] >= '0' && p[1] <= '9');
    if (!digit || (p[0] == '0' && (p[1] == 'x' || p[1] == 'X'))) {
        *end = (char *)s;
        errno = 0;
        return 0;
    }
    errno = 0;
    return strtod(s, end);
}
