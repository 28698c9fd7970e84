/* vwalls/common.h - status codes, export macro and the axis-aligned box.
 *
 * Every call that can fail returns a vw_status; results come back through
 * out-pointers. Names and messages come from one X-macro so they cannot drift apart.
 */
#ifndef VWALLS_COMMON_H
#define VWALLS_COMMON_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(VW_BUILDING_LIBRARY) && defined(__GNUC__)
#define VW_API __attribute__((visibility("default")))
#else
#define VW_API
#endif

/* VW_VERSION_MAJOR, _MINOR, _PATCH, _STRING: generated from the CMake project version. */
#include "vwalls/version.h"

/* X(name, message) */
#define VW_STATUS_MAP(X)                                              \
    X(OK, "success")                                                  \
    X(E_INVAL, "invalid argument")                                    \
    X(E_INPUT, "bad input")                                           \
    X(E_NOMEM, "out of memory")                                       \
    X(E_IO, "input/output error")                                     \
    X(E_STATE, "call not valid in the current state")                 \
    X(E_LIMIT, "limit exceeded")                                      \
    X(E_MPI, "MPI failure")                                           \
    X(E_PEER, "another process failed")                               \
    X(E_UNSUPPORTED, "not supported by this build")

typedef enum vw_status {
#define VW__STATUS_ENUM(name, msg) VW_##name,
    VW_STATUS_MAP(VW__STATUS_ENUM)
#undef VW__STATUS_ENUM
    VW_STATUS_COUNT
} vw_status;

VW_API const char *vw_status_name(vw_status s);
VW_API const char *vw_status_message(vw_status s);
VW_API const char *vw_version(void);

/* Test-only fault injection (sqlite3_test_control's role): nonzero when name is one of
   the comma-separated words of the environment variable VW_FAULT. The applications and
   the vwalls command force rare failures with it (VW_FAULT=solver-nomem: the radiosity
   solver's allocation fails; docs/runtime.md lists the words), so the tests can reach
   paths no real input reaches, such as memory that one process of an MPI job lacks.
   Never set outside tests. */
VW_API int vw_test_fault(const char *name);

/* Runs fn(i, user) for every i in [0, n), each on a thread of its own (i = 0 on the
   calling thread), and returns when all have: for a serial phase split over the
   workers, which are idle then. A part whose thread cannot be started runs on the
   calling thread; n above 64 runs every part there. */
VW_API void vw_parallel(int n, void (*fn)(int i, void *user), void *user);

/* strtod for numbers in decimal notation only, the one reading of a real number for the
   command line, --speeds, the scene readers and the edit language: s must begin with a
   digit, or with '-' or '.' before one (a '+' too when plus is nonzero: exporters write
   one in data files; the command line refuses it, as it does in whole numbers). White
   space first, C99 hexadecimal floats ("0x10" would be 16), "inf" and "nan" are no
   conversion: *end = s and 0 is returned. Otherwise as strtod, errno included. */
VW_API double vw_strtod_decimal(const char *s, char **end, int plus);

/* A closed axis-aligned box [lo, hi]. */
typedef struct vw_box {
    double lo[3], hi[3];
} vw_box;

#ifdef __cplusplus
}
#endif
#endif
