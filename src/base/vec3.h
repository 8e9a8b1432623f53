/* vec3.h: inline 3-D vector arithmetic on pd_vec3 (private to the library and
 * its tests). Kept as plain functions so the compiler inlines them and so no
 * expression is contracted into an FMA (-ffp-contract=off): results are the
 * same on every machine. */
#ifndef PD_VEC3_H
#define PD_VEC3_H

#include <math.h>
#include "posedrop/types.h"

static inline pd_vec3 v3(double x, double y, double z) { pd_vec3 r = {x, y, z}; return r; }
static inline pd_vec3 v3_add(pd_vec3 a, pd_vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline pd_vec3 v3_sub(pd_vec3 a, pd_vec3 b) { return v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline pd_vec3 v3_scale(pd_vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static inline pd_vec3 v3_neg(pd_vec3 a) { return v3(-a.x, -a.y, -a.z); }
static inline double v3_dot(pd_vec3 a, pd_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
/* fmin and fmax per component, inline (libm's are calls through the PLT,
 * which bounding-box loops over millions of corners paid for): the same
 * results, a NaN on either side giving the other. */
static inline double v3_fmin1(double a, double b) { return b < a || a != a ? b : a; }
static inline double v3_fmax1(double a, double b) { return b > a || a != a ? b : a; }
static inline pd_vec3 v3_min(pd_vec3 a, pd_vec3 b)
{
    return v3(v3_fmin1(a.x, b.x), v3_fmin1(a.y, b.y), v3_fmin1(a.z, b.z));
}
static inline pd_vec3 v3_max(pd_vec3 a, pd_vec3 b)
{
    return v3(v3_fmax1(a.x, b.x), v3_fmax1(a.y, b.y), v3_fmax1(a.z, b.z));
}
static inline pd_vec3 v3_cross(pd_vec3 a, pd_vec3 b)
{
    return v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline double v3_norm(pd_vec3 a) { return sqrt(v3_dot(a, a)); }
static inline double v3_dist(pd_vec3 a, pd_vec3 b) { return v3_norm(v3_sub(a, b)); }
/* a / |a|; the zero vector stays zero rather than becoming NaN. */
static inline pd_vec3 v3_unit(pd_vec3 a)
{
    double n = v3_norm(a);
    return n > 0.0 ? v3_scale(a, 1.0 / n) : a;
}
static inline pd_vec3 v3_lerp(pd_vec3 a, pd_vec3 b, double t)
{
    return v3_add(a, v3_scale(v3_sub(b, a), t));
}
/* Angle between two nonzero vectors, accurate at 0 and pi (atan2 of |a x b|
 * and a.b, unlike acos of a normalised dot product). */
static inline double v3_angle(pd_vec3 a, pd_vec3 b)
{
    return atan2(v3_norm(v3_cross(a, b)), v3_dot(a, b));
}
static inline int v3_isfinite(pd_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

#endif
