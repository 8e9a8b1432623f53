/* predicates.h (private): the exact orientation predicate of the convex hull.
 *
 * Every visibility decision of the hull goes through pd_orient3d, whose sign
 * is the sign of the exact determinant of the double inputs. Deciding in
 * floating point alone lets round-off call a point "outside" of two facets
 * that disagree, and the hull then stops being convex or even closed. */
#ifndef PD_PREDICATES_H
#define PD_PREDICATES_H

#include <float.h>
#include <math.h>
#include "posedrop/types.h"

/* Bound on the round-off of the filter below, relative to the permanent (the
 * same sum with every product made absolute). Derivation: each of u, v, w is a
 * rounded difference (1 rounding each), a term u*(v*w) carries those three and
 * two products, the 2x2 minor one subtraction and the final sum two additions:
 * at most 8 roundings of relative size 2^-53 on terms bounded by the
 * permanent, plus second-order terms. 8 * DBL_EPSILON = 16 * 2^-53 is twice
 * that, so the bound holds with room for the rounding of the permanent itself.
 * Shewchuk's tighter analysis of the same expression gives (7 + 56 eps) eps. */
#define PD_ORIENT3D_FILTER_REL (8.0 * DBL_EPSILON)

/* Absolute part of the filter bound: a product that underflows into the
 * subnormal range is wrong by up to half a subnormal step rather than by a
 * relative amount; 32 such steps cover the 12 products and 5 sums. */
#define PD_ORIENT3D_FILTER_ABS (32.0 * DBL_TRUE_MIN)

/* Sign of the exact (b - a) x (c - a) . (d - a) by expansion arithmetic. */
int pd_orient3d_exact(const pd_vec3 *a, const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d);

/* +1 when d lies on the side of the plane abc that the normal
 * (b - a) x (c - a) points to (a, b, c counter-clockwise seen from d),
 * -1 on the other side, 0 exactly on the plane. Exact for all finite input
 * whose products do not overflow. The filter decides almost every call; only
 * when |det| is within its error bound does the exact fallback run. */
static inline int pd_orient3d(const pd_vec3 *a, const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d)
{
    double ux = b->x - a->x, uy = b->y - a->y, uz = b->z - a->z;
    double vx = c->x - a->x, vy = c->y - a->y, vz = c->z - a->z;
    double wx = d->x - a->x, wy = d->y - a->y, wz = d->z - a->z;
    double vywz = vy * wz, vzwy = vz * wy;
    double vzwx = vz * wx, vxwz = vx * wz;
    double vxwy = vx * wy, vywx = vy * wx;
    double det = ux * (vywz - vzwy) + uy * (vzwx - vxwz) + uz * (vxwy - vywx);
    double perm = fabs(ux) * (fabs(vywz) + fabs(vzwy)) + fabs(uy) * (fabs(vzwx) + fabs(vxwz)) +
                  fabs(uz) * (fabs(vxwy) + fabs(vywx));
    double bound = PD_ORIENT3D_FILTER_REL * perm + PD_ORIENT3D_FILTER_ABS;
    if (det > bound)
        return 1;
    if (det < -bound)
        return -1;
    return pd_orient3d_exact(a, b, c, d);
}

/* The same predicate with the triangle's part precomputed, for testing many
 * points d against one triangle: n = (b - a) x (c - a) rounded, and nperm its
 * permanent (|uy vz| + |uz vy|, ...). Bound: n carries <= 4 roundings of
 * 2^-53 relative to nperm, w = d - a one, the dot product three: 8 * 2^-53 of
 * nperm . |w|, and PD_ORIENT3D_FILTER_REL is twice that. */
static inline int pd_orient3d_plane(const pd_vec3 *n, const pd_vec3 *nperm, const pd_vec3 *a,
                                    const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d)
{
    double wx = d->x - a->x, wy = d->y - a->y, wz = d->z - a->z;
    double det = n->x * wx + n->y * wy + n->z * wz;
    double bound = PD_ORIENT3D_FILTER_REL * (nperm->x * fabs(wx) + nperm->y * fabs(wy) + nperm->z * fabs(wz)) +
                   PD_ORIENT3D_FILTER_ABS;
    if (det > bound)
        return 1;
    if (det < -bound)
        return -1;
    return pd_orient3d_exact(a, b, c, d);
}

#endif
