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

/* A knife facet (the centre of mass's foot within PD_TOL_KNIFE_REL of its
 * boundary) counts as unstable only where toppling across an edge of that
 * boundary lowers the centre of mass by more than this, relative to the
 * size L. Why 1e-13: heights are offset - n . com with both terms at most
 * ~2.6 L in the part's frame (positions within 1.5 L of its origin per axis),
 * so their round-off is a few ulps of that, ~2e-15 L; 1e-13 is 50 times
 * above. Below it, which neighbour is lower is decided by round-off: on a
 * flat regular pyramid the foot lies at the apex, within the knife band of
 * every side facet, and all of them are at one height; toppling each to a
 * neighbour of "lower" round-off made the graph a cycle. Exactly, those
 * facets are stable (the foot is inside each, by ~h^2 / r), and so they are
 * counted. A genuine knife across an edge of dihedral turn phi drops by
 * r phi^2 / 2 (r the centre's distance from the edge), above this for
 * phi > sqrt(2e-13 L / r), 1.4e-6 rad at r = 0.1 L; flatter edges with the
 * centre exactly over them are ambiguous at this precision either way. Larger: such knives would stay
 * stable more often; smaller: round-off would pick the way down again. */
#define PD_TOL_KNIFE_DROP_REL 1e-13

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

/* Signed distance of the centre of mass's foot on facet f from the line of
 * its edge i (loop corner i to i + 1), positive inside. */
double pd_facet_edge_inside(const pd_hull *hull, pd_vec3 com, int f, int i);

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
 * and .rest for all facets. A knife facet with no lower facet across its
 * boundary becomes stable (one warning counts them). Checks that every link lowers the centre of mass
 * (PD_ERR_INTERNAL otherwise) and that descent ends (PD_ERR_NO_CONVERGENCE). */
pd_status pd_topple_graph(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                          pd_topple_rule rule, pd_static_result *res, pd_diag *diag);

/* PQS: redistributes p_raw by the perturbation bands into pert[] (one entry
 * per facet, before propagation down the graph). */
pd_status pd_pqs_perturb(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                         const pd_static_options *opt, const pd_static_result *res,
                         double *pert, pd_diag *diag);

/* 1 when the band of stable facet i along its edge shared with facet j moves
 * to j: j is unstable, or starts strictly more probable (beyond a relative
 * tie), by opt->compare's measure. */
int pd_pqs_moves(const pd_static_options *opt, const pd_static_result *res, int i, int j);

/* Exact spherical area of the part of triangle (A, B, N) (unit vectors, N on
 * the positive side of the great circle AB) within angle eps of that circle. */
pd_status pd_band_area_exact(pd_vec3 A, pd_vec3 B, pd_vec3 N, double eps, double *area);

#endif
