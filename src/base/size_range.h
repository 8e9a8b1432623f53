/* size_range.h (private): the sizes of part the library supports.
 *
 * The size L is the diagonal of the bounding box of the part's points, in
 * metres. Inside [PD_SIZE_MIN, PD_SIZE_MAX] every tolerance is relative to L
 * and the results are those of the part at 1 m scaled, to round-off; outside
 * it the mesh, hull and part builders refuse with PD_ERR_RANGE and a message
 * naming the range (docs/limits.md).
 *
 * Why 1e-30 and 1e30: the library forms products of lengths, and each must
 * stay a normal double (2.2e-308 to 1.8e308) to keep its relative precision.
 * The deepest are of ten: the inertia per unit density is a length^5
 * (mesh/mass.c), and the flight's invariants square an angular momentum
 * (inertia times a rate). Over [1e-30, 1e30] L^10 stays within
 * [1e-300, 1e300], which leaves 1e8 for constant factors and for features
 * smaller than L. Beyond, measured on cubes: unit normals come out 1.0025
 * long at 1e-81 m (their cross products' squares, L^4, are subnormal), the
 * inertia underflows below ~1e-61 m and overflows above ~1e61 m, and from
 * ~1e77 m the squared cross products overflow and every point seems to lie
 * on one plane. No physical part is within 20 orders of magnitude of either
 * end (an atom is 1e-10 m, a galaxy 1e21 m), so nothing real is refused. */
#ifndef PD_SIZE_RANGE_H
#define PD_SIZE_RANGE_H

#include "posedrop/diag.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#define PD_SIZE_MIN 1e-30
#define PD_SIZE_MAX 1e30

/* PD_OK if the points spanning the box [lo, hi] (finite coordinates) have a
 * size within the range or exactly 0 (coincident points, which the callers
 * refuse in their own words); else PD_ERR_RANGE with a message, prefixed by
 * what, that gives the size (or says that it overflows a double) and the
 * range. */
pd_status pd_size_check(pd_vec3 lo, pd_vec3 hi, const char *what, pd_diag *diag);

#endif
