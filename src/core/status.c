/* status.c - names and messages of vw_status, generated from VW_STATUS_MAP so the
 * two tables cannot drift apart; and the library version.
 */
#include "vwalls/common.h"

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
