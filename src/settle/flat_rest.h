/* flat_rest.h (private): a second test that a drop's outcome is decided, for
 * a part lying flat on a stable facet.
 *
 * The energy test (basin.h) must wait until all the kinetic energy, sliding
 * included, is below the basin's barrier, so a part that lands flat and
 * slides pays for every microcollision of the slide. But a part flat on a
 * facet with its centre of mass well inside it cannot be tipped by sliding:
 * friction pulls at the floor with at most mu m g, a torque of at most
 * mu m g h about the centre of mass (h its height), and a spin about the
 * vertical needs a gyroscopic torque bounded by the spin's energy, which
 * friction only takes away. If the centre of pressure those torques need
 * stays inside the facet, a non-negative pressure holds the part flat, and
 * the slide ends on that facet. flat_rest.c states the bounds. */
#ifndef PD_FLAT_REST_H
#define PD_FLAT_REST_H

#include "dynamics/body.h"
#include "posedrop/hull.h"
#include "posedrop/static.h"

/* What the test needs of one facet, body frame (principal, origin at the
 * centre of mass). Only stable facets (rest == itself) have inside > 0. */
typedef struct pd_flat_facet {
    pd_vec3 n;     /* outward normal */
    double h;      /* height of the centre of mass above the facet's plane, m */
    double inside; /* distance from the centre of mass's foot to the facet's boundary, m */
    double reach;  /* largest distance of a corner from the centre of mass's vertical, m */
    double inn;    /* moment of inertia about the normal, kg m^2 */
    double tilt;   /* |I n - inn n|: how far the normal is from a principal axis, kg m^2 */
} pd_flat_facet;

/* One entry per hull facet into out (nfacets entries). */
void pd_flat_build(const pd_body *b, const pd_hull *hull, const pd_static_result *descent,
                   pd_flat_facet *out);

/* A height of the centre of mass above the floor, m, at and above which
 * pd_flat_settled refuses whatever the facet and the motion (its test needs
 * the centre of mass within a facet's barrier of lying flat on it), so a
 * caller may skip finding the facet. -INFINITY if no facet is stable. */
double pd_flat_height_max(const pd_flat_facet *ff, int nfacets);

/* 1 if state s lies on stable facet f, flat up to a rocking energy that
 * cannot tip it, and so stays there for good under friction mu and gravity g:
 * its outcome is facet f. rest_fall is the depth a resting contact may have
 * sunk (drop.c). */
int pd_flat_settled(const pd_flat_facet *ff, const pd_body *b, const pd_state *s, int f, double g,
                    double mu, double rest_fall);

#endif
