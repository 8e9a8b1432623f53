/* dynamics_tol.h (private): tolerances of the body model, the closed-form
 * flight and the search for the next impact. Conventions as in
 * posedrop/tolerances.h: lengths relative to the part's size L. */
#ifndef PD_DYNAMICS_TOL_H
#define PD_DYNAMICS_TOL_H

#include "posedrop/tolerances.h"

/* Principal moments that differ by at most this fraction of the largest are
 * made exactly equal when the dynamic body model is built, so the flight takes
 * the closed-form symmetric-top or spherical branch. Why 1e-12: a cube's or a
 * cylinder's computed moments differ by round-off (~1e-15 relative). Treating a
 * body of true asymmetry d as symmetric moves it by about d |w| t radians: 1e-10
 * rad after 2 s at 50 rad/s, far below anything a drop resolves. Smaller:
 * round-off asymmetry would reach the elliptic branch, whose integral of the
 * third kind has parameter n = (J1 - J2)/(J2 - J3) up to 1e15 there and loses
 * digits. Larger (1e-6 and up): genuinely asymmetric parts would lose their
 * tumbling (tennis-racket) motion. */
#define PD_TOL_INERTIA_SYM_REL 1e-12

/* An angular momentum whose direction is within this (unit vector
 * components) of a principal axis is a steady spin about that axis, taken in
 * closed form. Why 1e-12: a contact phase rotating a part about an edge along
 * a principal axis ends with off-axis components of round-off (~1e-14); about
 * the middle axis that is the elliptic solution's separatrix, where the
 * phase's integral F(am, 1) = atanh(sin am) needs sin am = 1 - 1e-28 and
 * overflows. Snapping keeps the unstable spin steady: a 1e-12 perturbation
 * would grow at most e^(|w| t), to 1e-8 rad after 2 s at 10 rad/s. Smaller:
 * the overflow; larger: genuine wobbles would be dropped. */
#define PD_TOL_FLIGHT_AXIS_REL 1e-12

/* Where the closed form fails near the separatrix (the elliptic phase of a
 * state within round-off of its end, the middle axis, overflows), a spin
 * whose L is within this of a principal axis is taken as steady instead.
 * Why 1e-6: contact phases that rotate a part about an edge along its middle
 * axis leave off-axis components of their integration error, ~1e-8; the
 * steady spin then errs by 1e-6 e^(lambda t), lambda <~ |w| the growth rate
 * of the middle axis's instability: 1.6e-6 rad after a 0.1 s flight at 10
 * rad/s (flights after a contact are that short). Only used where the
 * exact form has failed; larger would hide genuine tumbling. */
#define PD_TOL_FLIGHT_NEAR_AXIS_REL 1e-6

/* The asymmetric top's flight evaluates its elliptic functions and its
 * precession by Jacobi's theta series in the nome q (flight_theta.c) while q
 * is at most this; beyond, on the separatrix itself, by GSL's Legendre
 * integrals. Dimensionless: q depends on the inertia ratios and the energy
 * only, not on the part's size. Why 0.8: q = 0.8 is 1 - m ~ 1e-18, below
 * the resolution of m near 1 in double precision, so every polhode that is
 * not the separatrix takes the series (whose 1 - m is computed without
 * cancellation; GSL's forms, handed m alone, err there by up to 0.1 rad
 * against an ODE after 100 rad of turning). The cost: theta4(v) near v = 0
 * shrinks to sqrt(2 k' K / pi), 1.2e-4 at q = 0.8, out of terms of order 1,
 * so sn, cn, dn lose 4 digits there (energy and momentum then hold to 1e-11,
 * measured, within their 1e-10), and 14 terms reach PD_TOL_FLIGHT_SERIES.
 * Larger: both grow without bound (at q = 0.9, 9 digits and 20 terms).
 * Smaller: the Legendre forms' errors near the separatrix come back. */
#define PD_FLIGHT_NOME_MAX 0.8

/* A theta series stops at the first term k with q^(k^2) below this, which
 * bounds that term (and so, geometrically, the rest) relative to the
 * series' leading one. Dimensionless: the series give unit vectors and
 * angles. Why 1e-17: below the double-precision round-off (1.1e-16) of the
 * sums themselves, so truncation adds nothing to it. Larger: the flight's
 * orientation would err by the truncation (1e-12 at 1e-12); smaller costs
 * terms that round-off swallows. */
#define PD_TOL_FLIGHT_SERIES 1e-17

/* The time of impact is found when the lowest hull vertex is within this height
 * of the floor, approached from above (never below it by more). Why 1e-9: the
 * flight's positions carry round-off of ~1e-15 L at drop heights of a few L and
 * its orientation ~1e-14 rad, so heights are known to ~1e-14 L: a margin of 1e5.
 * The impact time is then known to 1e-9 L / (approach speed). Larger: the
 * collision is applied with a visible gap (at 1e-5 L a resting part would
 * hover and re-collide in ever shorter flights). Smaller (below ~1e-13): the
 * search would chase round-off and stop on its iteration limit. */
#define PD_TOL_IMPACT_REL 1e-9

/* The lowest vertex (pd_body_support, src/dynamics/body.c) is found by
 * hill-climbing the hull's edges, then checking the other corners of the
 * facets around it, since a facet bent by up to PD_TOL_PLANE_REL can hide a
 * lower corner behind a diagonal. The check is skipped at a vertex whose
 * facets all keep every corner within this distance (times L) of the plane
 * through the vertex and its two neighbours on the facet, and inside their
 * angle: no corner can then lie lower than the vertex by more than this.
 * Further corners can, by this times a factor of the facets' shape (22 on a
 * 32-gon's cap bent on purpose, where 3e-8 L of bend left the climb 7e-7 L
 * high without the check). Why 1e-13: exactly planar faces (a file's equal
 * coordinates) come out of the principal-axes rotation bent by round-off, at
 * most 6e-18 L on a 32-gon coin's caps and 4e-17 L on the shipped parts' flat
 * faces, over 2000 times below; a face whose file prints 12 digits is bent by
 * up to 1e-12 L and keeps its check. The height the impact search reads is
 * then at most ~2e-12 L above the true lowest on such a cap, 400 times below
 * PD_TOL_IMPACT_REL. Larger: a slightly bent face could hand the search a
 * height off by a visible part of its tolerance. Smaller: round-off on faces
 * of many corners (where it grows with the corners' count) would bring the
 * check back where it cannot change the answer. */
#define PD_TOL_SUPPORT_FLAT_REL 1e-13

/* Conservative-advancement steps one impact search may take before it reports
 * PD_ERR_NO_CONVERGENCE. Each step closes at least the fraction
 * (true approach speed)/(speed bound) of the remaining gap; a part whose
 * rotation bound exceeds its approach speed a hundredfold needs ~100 ln(1e9)
 * ~ 2000 steps to converge to PD_TOL_IMPACT_REL. 100000 is far above any
 * genuine search and still stops a runaway (NaN-free but stuck) state fast. */
#define PD_CONTACT_MAX_STEPS 100000

/* The flight's bound on |w| (flight.c, wmax_bound) leaves out a pair of
 * principal moments closer than this relative to the larger, and adds
 * PD_FLIGHT_WMAX_ROUND times 2 E / I_min to the bound's square. Why 1e-6 and
 * 1e-9: a pair's solution divides by the moments' difference, so its
 * round-off, ~1e-16 of 2 E / I_min over the relative difference, is at most
 * 1e-10 of 2 E / I_min for the pairs kept, ten times below the margin
 * added; the margin widens the bound by at most 1e-9 of the classical
 * energy bound (a needle of aspect 1000 at 3 rad/s: by 2e-3 rad/s). Closer
 * pairs are left out, as the set's other vertices then bound it. Larger
 * margin: looser bounds for parts of extreme inertia ratio; smaller: the
 * margin no longer covers the round-off. */
#define PD_FLIGHT_WMAX_PAIR_REL 1e-6
#define PD_FLIGHT_WMAX_ROUND 1e-9

#endif
