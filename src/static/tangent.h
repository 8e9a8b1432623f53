/* tangent.h (private): the exact first derivatives of the QS and PQS
 * probabilities along a smooth motion of the hull's vertices and of the
 * centre of mass (forward mode), for the design layer's sensitivities.
 *
 * QS and PQS are sums of spherical polygon areas (facets' solid angles and
 * PQS bands) whose corners are the hull's vertices seen from the centre of
 * mass; as long as the discrete structure holds (which facets are stable,
 * where each unstable one topples, which PQS bands move and whether a band
 * is its rectangle or its clipped triangle) each probability is a smooth
 * function of those points, and its derivative is the sum of the areas'
 * derivatives. The structure is taken from a pd_static_result of the same
 * part, and held fixed. */
#ifndef PD_STATIC_TANGENT_H
#define PD_STATIC_TANGENT_H

#include "posedrop/hull.h"
#include "posedrop/static.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

/* The solid angle of triangle (a, b, c) seen from the origin (as
 * pd_solid_angle_triangle) and its derivative along the motion (da, db, dc)
 * of its corners. */
double pd_solid_angle_triangle_d(pd_vec3 a, pd_vec3 b, pd_vec3 c, pd_vec3 da, pd_vec3 db,
                                 pd_vec3 dc, double *d);

/* Along the motion dv (hull->nverts vectors, one per hull vertex) and dcom
 * of the centre of mass: dp_raw[f] for every facet, dp_qs[f] and dp_pqs[f]
 * for every stable facet (0 for the others), res being pd_static_estimate's
 * result for this hull and com under opt. Facet planes move with their
 * corners (their Newell normal), which is exact for motions that keep each
 * facet planar (affine maps of the part, or of slabs cut between facets).
 * PD_ERR_USAGE for PD_PQS_BAND_EXACT (its band is a quadrature, not
 * differentiated here). Any of the three outputs may be NULL. */
pd_status pd_static_tangent(const pd_hull *hull, pd_vec3 com, const pd_static_options *opt,
                            const pd_static_result *res, const pd_vec3 *dv, pd_vec3 dcom,
                            double *dp_raw, double *dp_qs, double *dp_pqs);

#endif
