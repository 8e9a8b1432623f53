/* static_tol.h (private): tolerances of the static estimators' internals.
 * The ones that shape their results (knife edges, probability ties) are
 * public in posedrop/tolerances.h; conventions as there. */
#ifndef PD_STATIC_TOL_H
#define PD_STATIC_TOL_H

#include "posedrop/tolerances.h"

/* Unit normals whose components differ by at most this are equal when poses
 * that tie in probability are ordered by normal. Why 1e-9: computed normals
 * carry round-off of ~1e-16 per component, so a mirror-symmetric pair must not
 * be ordered by noise; distinct facets differ by 1e-7 rad or more (see
 * PD_TOL_PLANE_REL), two orders above. */
#define PD_TOL_NORMAL_TIE 1e-9

/* pd_pose_transform takes the pose's normal as the rotation's third row, so
 * it must be a unit vector: one the library computed is, to ~1e-16; this
 * leaves room for a caller's own conversions (a float round trip gives
 * 1e-7: refused) and refuses a normal that was never normalised. */
#define PD_TOL_POSE_UNIT 1e-9

/* Descent must lower the centre of mass along every quasi-static link. A rise
 * smaller than this (relative to L) is accepted as error of the facet planes;
 * a larger one is reported as PD_ERR_INTERNAL. Why 2 PD_TOL_PLANE_REL: a
 * merged facet's plane is fitted to vertices up to PD_TOL_PLANE_REL L off it
 * (hull_merge.c), so its height is known only to that, and a link between two
 * such facets may seem to rise by the sum: a hexagonal prism whose points
 * carry 1e-5 L of noise has a link between cap facets that rises by 9e-9 L.
 * Larger: would hide a genuine descent bug; smaller: noisy parts fail. */
#define PD_TOL_HEIGHT_REL (2.0 * PD_TOL_PLANE_REL)

/* Exact PQS band: relative accuracy asked of the adaptive quadrature of the
 * band area. Why 1e-10: six orders below the relative tie tolerance that
 * decides transfers (PD_TOL_PROB_TIE_REL, 1e-4), so the quadrature's error
 * never decides a tie; above what GSL's 21-point rule reaches on smooth
 * integrands. */
#define PD_TOL_BAND_QUAD_REL 1e-10

#endif
