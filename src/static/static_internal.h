/* static_internal.h (private): the pieces pd_static_estimate is built from.
 *
 * facet.c classifies each hull facet (area, height, stability, the feature of
 * its boundary nearest the projected centre of mass), topple.c builds the
 * quasi-static graph from that, pqs.c computes the perturbation bands. They
 * share the per-facet record below; static.c runs them in order. */
#ifndef PD_STATIC_INTERNAL_H
#define PD_STATIC_INTERNAL_H

#include "posedrop/diag.h"
#include "hull/star.h"
#include "posedrop/hull.h"
#include "posedrop/static.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

/* Where the centre of mass projects relative to one facet's polygon. */
typedef struct facet_geom {
    pd_vec3 foot;    /* projection of the centre of mass onto the facet plane */
    pd_vec3 nearest; /* point of the facet polygon nearest the foot (the foot
                        itself when it lies inside) */
    double inside;   /* signed distance of foot from the nearest edge line,
                        positive inside the polygon (min over the edges) */
    int near_edge;   /* loop position k of the boundary edge (corner k to k+1)
                        nearest the foot */
    int near_vertex; /* -1 if the nearest boundary point is inside that edge,
                        else the hull vertex index it is */
    int best_edge;   /* loop position of the edge beyond whose line foot lies
                        farthest: the paper's toppling edge */
} facet_geom;

/* Fills g and the area, height, stable and knife fields of r for facet f. */
void pd_facet_classify(const pd_hull *hull, pd_vec3 com, int f, facet_geom *g,
                       pd_facet_result *r);

/* Solid angle of facet f's polygon seen from com, fanned from the facet's
 * point nearest com (see solid_angle.c for why). */
double pd_solid_angle_facet(const pd_hull *hull, pd_vec3 com, int f, pd_vec3 nearest);

/* Solid angle seen from the origin of triangle (q, b, c), where q is the
 * point of a convex facet containing b and c that is nearest the origin. */
double pd_solid_angle_from_nearest(pd_vec3 q, pd_vec3 b, pd_vec3 c);

/* Steepest descent of the centre of mass height from any gravity direction g
 * (unit, part frame): the facet the part first lands on (whose rest[] then
 * names the stable pose). hint (may be NULL) is a vertex to start the support
 * search from and receives the support vertex of g, so that successive calls
 * with nearby g cost little. PD_ERR_NO_CONVERGENCE or PD_ERR_INTERNAL only on
 * a bug. */
pd_status pd_descend(const pd_hull *hull, const pd_star *star, pd_vec3 com, pd_vec3 g,
                     int *facet, int *hint);

/* The quasi-static successor of every unstable facet: res->facets[f].next,
 * and .rest for all facets. Checks that every link lowers the centre of mass
 * (PD_ERR_INTERNAL otherwise) and that descent ends (PD_ERR_NO_CONVERGENCE). */
pd_status pd_topple_graph(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                          pd_topple_rule rule, pd_static_result *res, pd_diag *diag);

/* PQS: redistributes p_raw by the perturbation bands into pert[] (one entry
 * per facet, before propagation down the graph). */
pd_status pd_pqs_perturb(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                         const pd_static_options *opt, const pd_static_result *res,
                         double *pert, pd_diag *diag);

/* Exact spherical area of the part of triangle (A, B, N) (unit vectors, N on
 * the positive side of the great circle AB) within angle eps of that circle. */
pd_status pd_band_area_exact(pd_vec3 A, pd_vec3 B, pd_vec3 N, double eps, double *area);

#endif
