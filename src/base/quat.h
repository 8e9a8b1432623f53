/* quat.h: inline unit-quaternion arithmetic for orientations (private to the
 * library and its tests).
 *
 * A quaternion q = (w, x, y, z) with |q| = 1 stands for the rotation that takes
 * body-frame coordinates to world coordinates: v_world = q v_body q*. The
 * product a * b applies b first, then a (Hamilton convention). Plain functions
 * like vec3.h, so nothing is contracted into an FMA. */
#ifndef PD_QUAT_H
#define PD_QUAT_H

#include <math.h>
#include "posedrop/types.h"
#include "base/vec3.h"

typedef struct pd_quat {
    double w, x, y, z;
} pd_quat;

static inline pd_quat quat(double w, double x, double y, double z)
{
    pd_quat q = {w, x, y, z};
    return q;
}
static inline pd_quat quat_identity(void) { return quat(1.0, 0.0, 0.0, 0.0); }
static inline pd_quat quat_conj(pd_quat q) { return quat(q.w, -q.x, -q.y, -q.z); }
static inline double quat_norm(pd_quat q)
{
    return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}
/* q / |q|; the zero quaternion becomes the identity rather than NaN. */
static inline pd_quat quat_normalize(pd_quat q)
{
    double n = quat_norm(q);
    if (!(n > 0.0))
        return quat_identity();
    return quat(q.w / n, q.x / n, q.y / n, q.z / n);
}
static inline pd_quat quat_mul(pd_quat a, pd_quat b)
{
    return quat(a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
                a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w);
}
/* Rotation by angle (radians) about a unit axis. */
static inline pd_quat quat_axis_angle(pd_vec3 axis, double angle)
{
    double s = sin(0.5 * angle);
    return quat(cos(0.5 * angle), axis.x * s, axis.y * s, axis.z * s);
}
/* Rotation by the vector rv (axis rv/|rv|, angle |rv|): the exponential map.
 * Near zero the axis is not needed: sin(a/2)/a is evaluated as a series so a
 * tiny rotation keeps its full relative precision. */
static inline pd_quat quat_exp(pd_vec3 rv)
{
    double a = v3_norm(rv);
    double s;
    if (a < 1e-4)
        s = 0.5 - a * a / 48.0; /* sin(a/2)/a, next term a^4/3840 < 3e-20 */
    else
        s = sin(0.5 * a) / a;
    return quat(cos(0.5 * a), rv.x * s, rv.y * s, rv.z * s);
}
/* q v q*, expanded (t = 2 q_v x v; v + w t + q_v x t): 15 multiplies. */
static inline pd_vec3 quat_rotate(pd_quat q, pd_vec3 v)
{
    pd_vec3 u = v3(q.x, q.y, q.z);
    pd_vec3 t = v3_scale(v3_cross(u, v), 2.0);
    return v3_add(v3_add(v, v3_scale(t, q.w)), v3_cross(u, t));
}
/* q* v q: world to body. */
static inline pd_vec3 quat_rotate_inv(pd_quat q, pd_vec3 v) { return quat_rotate(quat_conj(q), v); }
/* Row-major rotation matrix of a unit quaternion. */
static inline void quat_to_matrix(pd_quat q, double R[3][3])
{
    double xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    R[0][0] = 1.0 - 2.0 * (yy + zz);
    R[0][1] = 2.0 * (xy - wz);
    R[0][2] = 2.0 * (xz + wy);
    R[1][0] = 2.0 * (xy + wz);
    R[1][1] = 1.0 - 2.0 * (xx + zz);
    R[1][2] = 2.0 * (yz - wx);
    R[2][0] = 2.0 * (xz - wy);
    R[2][1] = 2.0 * (yz + wx);
    R[2][2] = 1.0 - 2.0 * (xx + yy);
}
/* Unit quaternion of a proper rotation matrix (Shepperd's method: branch on
 * the largest of w^2, x^2, y^2, z^2 so the square root never sees a small,
 * cancellation-ridden argument). */
static inline pd_quat quat_from_matrix(const double R[3][3])
{
    double tr = R[0][0] + R[1][1] + R[2][2];
    pd_quat q;
    if (tr >= R[0][0] && tr >= R[1][1] && tr >= R[2][2]) {
        double s = 2.0 * sqrt(1.0 + tr);
        q = quat(0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s,
                 (R[1][0] - R[0][1]) / s);
    } else if (R[0][0] >= R[1][1] && R[0][0] >= R[2][2]) {
        double s = 2.0 * sqrt(1.0 + R[0][0] - R[1][1] - R[2][2]);
        q = quat((R[2][1] - R[1][2]) / s, 0.25 * s, (R[0][1] + R[1][0]) / s,
                 (R[0][2] + R[2][0]) / s);
    } else if (R[1][1] >= R[2][2]) {
        double s = 2.0 * sqrt(1.0 + R[1][1] - R[0][0] - R[2][2]);
        q = quat((R[0][2] - R[2][0]) / s, (R[0][1] + R[1][0]) / s, 0.25 * s,
                 (R[1][2] + R[2][1]) / s);
    } else {
        double s = 2.0 * sqrt(1.0 + R[2][2] - R[0][0] - R[1][1]);
        q = quat((R[1][0] - R[0][1]) / s, (R[0][2] + R[2][0]) / s, (R[1][2] + R[2][1]) / s,
                 0.25 * s);
    }
    return quat_normalize(q);
}

#endif
