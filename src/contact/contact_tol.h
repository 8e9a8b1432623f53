/* contact_tol.h (private): tolerances of the contact phases.
 *
 * One vertex or edge in lasting contact with the floor is integrated as an
 * ODE in units of the part: length L, time sqrt(L/g), speed sqrt(g L). */
#ifndef PD_CONTACT_TOL_H
#define PD_CONTACT_TOL_H

/* Local error per step asked of the phase's integrator (rkck), absolute and
 * relative in those units. Why 1e-8: what matters is the error a whole phase
 * leaves, against the rest-fall margin (1e-4 L) the energy test allows for.
 * Against the same phases integrated by rk8pd at 1e-14, a phase errs by at
 * most 5e-8 in the state, 2e-7 in the rate of turn and 1.4e-8 m g L in
 * energy (cube, box and coin drops); even the coin's 16 phases per drop, all
 * erring upwards, stay ~400x inside the margin, and sticking phases, which
 * conserve energy, drift by the same 1e-8. Larger: that margin shrinks in
 * step (the error grows as about tol). Smaller: costs steps, ~tol^(-1/5)
 * (1e-9 takes 1.3x the instructions per phase, 1e-10 1.8x). */
#define PD_TOL_PHASE_ODE_REL 1e-8

/* A phase starts from microcollision chatter by projecting the velocities
 * onto the contact constraints, an inelastic impulse; it is admitted only if
 * it takes at most this times m g L of kinetic energy. Why 1e-5: a tenth of
 * what the microcollision it replaces takes (a contact stopped from the
 * speed of a rest fall loses about m g rest_fall = 1e-4 m g L), so entering
 * damps less than going on. The paper's cap reads the same at 1e-7, 1e-5
 * and 1e-4, while the cube's collisions per drop fall by a third from 1e-7 to
 * 1e-5 (docs/validation.md, "Rest fall"). Larger: towards the damping of an
 * unlimited projection; smaller: fewer phases, more microcollisions. */
#define PD_TOL_PHASE_ENTRY_REL 1e-5

/* A phase ends when a contact's slip falls below this times sqrt(g L): near
 * zero slip friction's direction turns ever faster (the ODE stiffens) and the
 * contact may stick, which the collision law decides. Why 1e-3: at that slip
 * the part moves 1e-3 L per unit time, so handing over costs a few
 * microcollisions; smaller would make the phase chase the stiff turn. A phase
 * starts only at twice this, so it cannot start and end at once. */
#define PD_TOL_PHASE_SLIP_REL 1e-3

/* A phase hands over at most this long before its event (lift-off,
 * sticking, a new contact), in units of sqrt(L/g). Why 1e-6: the state is
 * then within ~1e-6 L of the event, the same order as the contact
 * tolerance. Each retry aims half this short of the event's estimate. */
#define PD_TOL_PHASE_EVENT_REL 1e-6

/* An event is estimated from the margins' values and rates of change at
 * both ends of a step; a rate is a forward difference along the motion over
 * this time, in units of sqrt(L/g). Why 1e-7: the margins and their rates
 * are O(1) in the part's units, so the difference is off by ~1e-7 of the
 * margin's second derivative (truncation) plus ~1e-16 / 1e-7 = 1e-9
 * (round-off); a rate off by d moves the estimate by about d times the
 * step, far below the event tolerance. */
#define PD_TOL_PHASE_RATE_STEP 1e-7

/* A phase's contact forces solve a system of at most 6 unknowns (the
 * contacts' response to unit forces); a pivot below this fraction of its
 * largest entry is singular and ends the phase (the microcollisions go on).
 * Why 1e-13: the entries are ~1/m and well scaled (body frame, moments of
 * the part's own size), so genuine pivots stay far above round-off (~1e-16);
 * a system that loses rank (as in Painleve's paradox, where friction makes
 * the normal response vanish) lands near 0.
 * Larger: healthy phases would be refused; smaller: forces near 1/round-off. */
#define PD_TOL_PHASE_PIVOT_REL 1e-13

/* Integrator steps one phase may take: bounded work per phase. Why 10000: a
 * sliding phase takes tens of steps; a phase that reaches this ends and the
 * microcollisions go on, so nothing is lost but time. */
#define PD_PHASE_MAX_STEPS 10000

#endif
