/* hull_mass.h (private): the solid convex hull's volume and second moments. */
#ifndef PD_HULL_MASS_H
#define PD_HULL_MASS_H

#include "posedrop/hull.h"

/* The volume of the solid hull and its second moment about point c,
 * S = integral of (x - c)(x - c)^T over the hull, per unit density (the
 * inertia tensor about c is trace(S) Id - S). */
void pd_hull_moments(const pd_hull *h, pd_vec3 c, double *volume, double S[3][3]);

#endif
