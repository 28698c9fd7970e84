/* status.c - names and messages of vw_status, generated from VW_STATUS_MAP so the
 * two tables cannot drift apart; and the library version.
 */
#include <stdio.h>
#include <string.h>
#include "vwalls/engine.h"

static const char *const status_names[] = {
#define VW__NAME(name, msg) "VW_" #name,
    VW_STATUS_MAP(VW__NAME)
#undef VW__NAME
};

static const char *const status_messages[] = {
#define VW__MSG(name, msg) msg,
    VW_STATUS_MAP(VW__MSG)
#undef VW__MSG
};

const char *vw_status_name(vw_status s)
{
    if ((unsigned)s >= VW_STATUS_COUNT) return "VW_UNKNOWN";
    return status_names[s];
}

const char *vw_status_message(vw_status s)
{
    if ((unsigned)s >= VW_STATUS_COUNT) return "unknown status";
    return status_messages[s];
}

const char *vw_version(void) { return VW_VERSION_STRING; }

void vw_errmsg_wrap(char *dst, size_t len, const char *what, const char *msg)
{
    if (!dst || !len) return;
    if (!msg) msg = "";
    size_t k = 5;
    if (!strncmp(msg, "rank ", 5))
        while (msg[k] >= '0' && msg[k] <= '9') k++;
    if (k > 5 && msg[k] == ':' && msg[k + 1] == ' ')
        snprintf(dst, len, "%.*s: %s: %s", (int)k, msg, what, msg + k + 2);
    else
        snprintf(dst, len, "%s: %s", what, msg);
}
