/* fault.c - the tests' fault switch: named failures (an allocation that fails on one
 * process only, say) forced through the environment, so the tests can reach error paths
 * that real inputs cannot. Read on error paths' set-up only, never in a hot loop.
 */
#include <stdlib.h>
#include <string.h>
#include "vwalls/common.h"

int vw_test_fault(const char *name)
{
    const char *v = getenv("VW_FAULT");
    size_t n = strlen(name);
    for (const char *p = v; p && *p; p += strcspn(p, ","), p += *p == ',')
        if (!strncmp(p, name, n) && (p[n] == ',' || !p[n])) return 1;
    return 0;
}
