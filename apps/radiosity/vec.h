/* vec.h - the few 3-vector operations the radiosity application uses, inline.
 * Internal to apps/radiosity; plain arrays of three doubles, no struct wrapper.
 */
#ifndef RAD_VEC_H
#define RAD_VEC_H

#include <math.h>

static inline double rad_dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void rad_sub(const double a[3], const double b[3], double out[3])
{
    for (int k = 0; k < 3; k++) out[k] = a[k] - b[k];
}
static inline void rad_cross(const double a[3], const double b[3], double out[3])
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    out[0] = x, out[1] = y, out[2] = z;
}
static inline double rad_norm(const double a[3]) { return sqrt(rad_dot(a, a)); }
static inline int rad_normalize(double a[3])
{
    double l = rad_norm(a);
    if (!(l > 0)) return 0;
    for (int k = 0; k < 3; k++) a[k] /= l;
    return 1;
}
static inline double rad_sum3(const double a[3]) { return a[0] + a[1] + a[2]; }

#endif
