/* impact_tol.h (private): tolerances of the frictional collision law.
 *
 * A collision is solved in units where |u0| = 1 (u0 the pre-impact contact
 * velocity) and K's mean diagonal is 1, so these are relative to |u0| and the
 * law stays homogeneous: scaling u0, the masses or the part changes no
 * decision taken here. */
#ifndef PD_IMPACT_TOL_H
#define PD_IMPACT_TOL_H

/* Local error per step asked of the sliding ODE (eq. 14 of the paper), both
 * absolute (in units of |u0|/K and |u0|^2/K) and relative. Why 1e-9: rk8pd's
 * error estimate is far above its error here, and the event tolerance, not
 * this, sets a collision's accuracy. Against a reference at 1e-13 with events
 * at 1e-12, on impacts recorded from drops and random ones, the impulse's
 * median error is 1e-13 and its maximum ~5e-10 (the events'), as at 1e-11,
 * for 30% fewer steps; the energetic law's bookkeeping error stays 200 times
 * below PD_TOL_IMPACT_ENERGY_REL. Larger (1e-8): the maximum error doubles,
 * past the events'. Smaller: steps for nothing; below ~1e-13 the controller
 * chases round-off of p (1e-16 times the condition number of K, up to 1e6).
 * The Taylor step between events (impact_slide.c) holds its last two terms
 * to the same bound: on 12109 impacts recorded from drops its worst impulse
 * error against a 1e-13 reference is 1.3e-9 |u0|/K, rk8pd's 2.9e-9. */
#define PD_TOL_IMPACT_ODE_REL 1e-9

/* Event location: sticking is declared when the tangential contact speed
 * falls to this fraction of |u0|; maximum compression and the end of an
 * energetic restitution when the normal velocity (resp. the normal work) is
 * within this fraction of |u0.z| (resp. of the compression work). Normal
 * events are relative to |u0.z|, not |u0|, so a grazing impact (|u0.z| =
 * 1e-12 |u0|) still rebounds with -e u0.z to this relative accuracy instead of
 * ending with the contact still approaching. Why 1e-9: the events are located
 * by Newton steps of the integrator, which converge quadratically, so the
 * cost does not depend on it; the integration error it must stay above is
 * the measured one, ~1e-13 (PD_TOL_IMPACT_ODE_REL), not the integrator's
 * requested tolerance. Larger: a part declared stuck at 1e-6 |u0| keeps that
 * slip in its state and the impulse carries a 1e-6 relative error. Smaller:
 * near the integration error, its noise would decide whether a near-miss of
 * the origin sticks. */
#define PD_TOL_IMPACT_EVENT_REL 1e-9

/* Largest number of integrator steps (accepted or refused for an event) one
 * collision may take before PD_ERR_NO_CONVERGENCE. Why 1000: collisions
 * recorded from drops take 3-12 steps on average and random impacts at most
 * ~36 (test_impact.c), since a stable stick approached along a slowly closing
 * invariant ray (stiff for an explicit integrator) is snapped onto that ray
 * or finished along it in closed form (impact_slide.c). 1000 bounds the
 * cost of a collision to ~1 ms and still stops a runaway; the drop then
 * resolves it by a counted fallback. */
#define PD_IMPACT_MAX_STEPS 1000

/* The slide's tail onto an incoming ray, a power series in the angle to the
 * ray (impact_ray_series.c), is built and tried within this angle (rad) of
 * it; it is used only where its own truncation estimate is below
 * PD_TOL_IMPACT_TAIL_REL (|u0|/K, the impulse's unit) and the angle within
 * half its radius of convergence, so the angle bounds the cost, not the
 * error. Why 1: on recorded and random impacts it takes a few percent fewer
 * steps than 0.5 and the fewest instructions, at the same maximum error.
 * Larger: past the radius of most rays' series (the nearest other invariant
 * ray), builds for nothing; smaller: slides integrated further, and below
 * ~0.1 the tail saves little. */
#define PD_TOL_IMPACT_SERIES_ANGLE 1.0

/* The ray tail's series is used only when its error estimate is at most
 * this, relative to |u0| like the event tolerance. Why a tenth of
 * PD_TOL_IMPACT_EVENT_REL: sticking is declared at that slip anyway, so the
 * tail then adds no error the event location does not already allow.
 * Larger: the tail's error would show beside the events'; smaller: more
 * slides integrated to the end, no change in results. */
#define PD_TOL_IMPACT_TAIL_REL (0.1 * PD_TOL_IMPACT_EVENT_REL)

/* The diverging ray is looked for (impact_slide.c) only where the slip's
 * direction may lie within the event tolerance of an invariant ray: the
 * turning rate b there (u_t x u_t' = s^2 b in tau) is at most the angle,
 * (pi/2) PD_TOL_IMPACT_EVENT_REL / s, times b's largest slope, bounded by
 * the flow's rate |a| + mu |B|. This factor stands for pi/2 with room for
 * the round-off of the ray (1e-16 of the flow's rate) and of the test,
 * against the 1e-9 of the tolerance: it decides where the ray is found,
 * never a result (every direction it passes is one the on-ray test
 * refuses). Larger: the ray found more often for nothing; below pi/2 the
 * on-ray test could be skipped where it holds. */
#define PD_IMPACT_ON_RAY_MARGIN 4.0

/* A direction is taken to lie in the diverging ray's basin
 * (pd_ray_in_basin) only when the cubic that vanishes at every other
 * invariant ray stays below zero by this share of the size of its terms
 * along the arc: its coefficients and values carry round-off of a few
 * 1e-16 of that size, so no ray within round-off of the arc is missed. It
 * decides only where the incoming rays are looked for (impact_slide.c),
 * never a result: a direction that fails it has them looked for, as
 * everywhere before. */
#define PD_TOL_IMPACT_BASIN_REL 1e-12

/* A collision "added energy" when its kinetic energy change p.(u0 + u1)/2
 * exceeds this fraction of |p| |u0| (the size of the work terms it is a sum
 * of). Why 1e-8: the energetic law's own bookkeeping error is the ODE's
 * (measured <= 5e-11); Poisson's genuine gains in 3-D are percent-level.
 * Larger would hide small genuine gains, smaller would flag integration
 * noise. */
#define PD_TOL_IMPACT_ENERGY_REL 1e-8

/* K must be symmetric to this fraction of its largest entry: it is assembled
 * from products of exact quantities, so asymmetry beyond round-off (1e-16)
 * means a caller's bug, e.g. a transposed inertia. */
#define PD_TOL_IMPACT_K_SYM_REL 1e-12

#endif
