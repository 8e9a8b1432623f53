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

/* A phase starting with the part turning faster than this many radians per
 * sqrt(L/g) is integrated by rk8pd rather than rkck (contact_phase.c). At
 * the phase tolerance rkck's steps turn the part by about 0.2 rad, so from
 * about 5 rad per sqrt(L/g) (where the first trial step, 0.05 sqrt(L/g),
 * turns it 0.25 rad) its steps are set by the turn, not by the phase's
 * events, and rk8pd's steps, about 4 times longer for twice the right-hand
 * sides, cost half as much: a 0.1 mm cube spinning as a top on a vertex at
 * 15 rad per sqrt(L/g) took 9.5-9.8 ms of CPU per simulated second with
 * rkck and 4.8-5.3 ms with rk8pd. Ordinary drops' phases start below 3 (the
 * cube, the 1 x 2 x 3 box, the coin and the cap, 300 drops each: at most
 * 3.0, 2.2, 2.2, 2.0), so they keep rkck, cheaper for their short phases. */
#define PD_PHASE_SPIN_FAST 5.0

/* A contact that starts to slide from rest (phase_forces.h,
 * pd_phase_slide_from_rest) takes a direction in which its tangential
 * acceleration stays along its slip: a zero of a cross product over the
 * circle of directions, found by a sign change between neighbouring ones of
 * this many, then narrowed to round-off. Why 36: times the normal force's
 * denominator the cross product is a trigonometric polynomial of degree 2,
 * with at most four zeros, so cells of 10 degrees miss only two zeros
 * closer than that, where the slide's direction is ill-defined anyway (the
 * phase is then refused, and microcollisions go on as before). Not a
 * setting: every zero found is exact to round-off. */
#define PD_PHASE_START_CELLS 36
/* An edge whose two contacts start to slide from rest: their directions by
 * Newton's method, from each contact's frictionless acceleration and, where
 * that fails, from the best common direction, at most this many iterations
 * each (quadratic convergence takes a handful from a start near the answer;
 * a planar slide, the common case, starts on it); not converged, the phase
 * is refused as before. */
#define PD_PHASE_START_NEWTON 30
/* ...converged when the two residuals (cross products of direction and
 * tangential acceleration, m/s^2) sum to at most this times g: the
 * accelerations' round-off is ~1e-16 of their few g, so 1e-12 is reached
 * in a step or two of quadratic convergence, and it turns the directions
 * by ~1e-12 rad, nothing the phase's 1e-8 error per step can see. */
#define PD_TOL_PHASE_START_RESIDUAL 1e-12
/* ...with the Jacobian from differences of this step in each angle (rad):
 * about the square root of the residual's relative round-off, where a
 * forward difference is most accurate. */
#define PD_PHASE_START_DIFF 1e-7

/* lands_first (contact_phase.c) judges a slide from rest by the first order
 * of the other vertices' heights over the time the slide takes to reach a
 * slide's speed; it is believed only where the part turns by less than this
 * (rad) over that time. Why 1 radian: the first order of a height that a
 * turn moves as sin(w t) is off by a sixth of it there and by more beyond,
 * where a spinning part's corners bob up and down within the horizon (a
 * 0.1 mm top on a corner turns thousands of radians over its slow slide's):
 * believed there, lands_first refused the slide at every start and
 * microcollisions carried the slip, 100,000 of them within seconds in 8 of
 * 200 drops. Ordinary parts turn far less: against a build that believed
 * it at any turn (and without the rest of the tops' changes), the cube,
 * box and coin ended on the same pose in each of 2000 drops, the cap in
 * 1986. */
#define PD_PHASE_LANDS_TURN 1.0

/* A pivot (two sticking contacts turning about their edge, contact_pivot.c)
 * is run in closed form: its force margins, functions of the angle alone
 * (trigonometric polynomials of degree 3 in it, and the cone's square root),
 * are sampled every PD_PIVOT_CELL rad along the motion for the first that
 * reaches zero. Why 0.02: a margin of amplitude M (its coefficients' sum)
 * bends by at most 9 M per rad^2, so one positive at both ends of a cell h
 * wide dips below zero inside it by at most 9 M h^2 / 8, 4.5e-4 M, over less
 * than the cell; the integrated pivot it replaced saw its margins at its
 * steps' ends alone, 0.015-0.03 rad apart (coin, cap, box: 0.0155, 0.0216,
 * 0.032 rad a step, 400 drops each), so the sampled cell is no coarser.
 * Every event found is then located to
 * PD_TOL_PIVOT_ANGLE (rad): the part moves by that times L, a thousandth of
 * the phase's tolerance per step, and the event's time by that over the
 * rate, far inside the event tolerance (the time at an angle is Legendre's
 * elliptic integral F, the angle at a time Jacobi's amplitude, both to
 * round-off). */
#define PD_PIVOT_CELL 0.02
#define PD_TOL_PIVOT_ANGLE 1e-11


/* --- compliant impacts (src/contact/compliant_law.c, compliant.c) ----------- */

/* Restitution below this is taken as this: at e = 0 the law's chi is
 * infinite (the contact never restores) and its duration with it. Why 0.01:
 * a rebound of 1% of the approach speed carries 1e-4 of the impact's energy,
 * below what any pose statistic resolves, while chi stays at 100 and a
 * contact takes about 210 of compliant.c's steps. */
#define PD_COMPLIANT_E_MIN 0.01

/* Relative accuracy of chi and tau: far below anything a drop resolves, and
 * cheap, since a run computes them once. */
#define PD_COMPLIANT_LAW_TOL 1e-13

/* rk8pd steps one contact may take: the scaled contact lasts a few units of
 * time and the steps at PD_COMPLIANT_LAW_TOL are ~0.05 long, so 1e5 only
 * stops a failure. */
#define PD_COMPLIANT_LAW_MAX_STEPS 100000

/* Trials of chi in its bracket (regula falsi, compliant_law.c), at most:
 * about 10 reach PD_COMPLIANT_LAW_TOL; 200 only stop a failure. */
#define PD_COMPLIANT_LAW_MAX_TRIALS 200

/* The step with one contact is, going up from short steps, the last whose
 * rebound from a flat landing (the scaled law, pd_compliant_law_step) is within
 * PD_COMPLIANT_E_TOL of the law's restitution, wherever in a step the
 * contact starts; with n contacts below the floor or coming below within
 * the step it is shortened by sqrt(n), since n springs of one contact's
 * stiffness on a rigid body vibrate up to sqrt(n) times faster (the trace
 * of their coupling), and with two by the square root of their fastest
 * mode's stiffness over one contact's (exact, compliant.c's pair_mode). Why
 * 1e-3: a rebound off by a thousandth of the approach speed, either sign by
 * where the touch falls in the step (the error averaged over the touch is
 * under 1e-6 at e = 0.3, 0.6, 0.9), is far below what a pose statistic
 * resolves (restitutions themselves are known to a few percent), and
 * halving the step moves no pose probability beyond sampling noise
 * (tests/unit/test_compliant.c). At e = 0.3 this is about 16 steps per
 * contact duration (a fixed 40 gave 1.5e-4), at e = 0.9 about 28 (15 gave
 * 5e-3), at e = 0.1 the bound below, 25 (98 gave 4e-7), at e = 0.01 212
 * (848).
 * PD_COMPLIANT_STEP_MAX bounds the step by the law's fastest rate, its
 * oscillation 1 / omega and its damping rate at the deepest (omega chi
 * s_peak): the explicit step is unstable beyond about 2, and at 1 it keeps
 * half of that in reserve for several contacts' coupling and the body's
 * turning. The touches tried are PD_COMPLIANT_STEP_PHASES evenly spread
 * over a step from its start (a touch at a step's start is the worst at
 * e = 0.3; between the touches tried the error varies smoothly). The search
 * starts PD_COMPLIANT_STEP_START times below the bound (the error there is
 * about its square times smaller), halving while that misses (at most
 * PD_COMPLIANT_STEP_TRIES times), doubles up to the first step that misses
 * and bisects to PD_COMPLIANT_STEP_REL of the step: the step moves less
 * than that with it, far less than the tolerance does. A step interpolated
 * in a table of laws that misses the tolerance is shortened by
 * PD_COMPLIANT_STEP_SHRINK at a time (a tenth: a few checks at most). */
#define PD_COMPLIANT_E_TOL 1e-3
#define PD_COMPLIANT_STEP_MAX 1.0
#define PD_COMPLIANT_STEP_PHASES 16
#define PD_COMPLIANT_STEP_START 64.0
#define PD_COMPLIANT_STEP_TRIES 60
#define PD_COMPLIANT_STEP_REL 1e-3
#define PD_COMPLIANT_STEP_SHRINK 0.9

/* Vertices within this times L above the floor are watched for contact, and
 * the list is rebuilt once the part may have moved half of it. Why 0.02: a
 * hull's vertices near the floor are few at that height, and rebuilds come
 * every 0.01 L of motion, a few hundred steps of a rocking part. Any value
 * gives the same motion (a vertex can only touch from within the band);
 * only the cost moves. */
#define PD_COMPLIANT_BAND_REL 0.02

/* Gauss-Seidel sweeps over the contacts' friction impulses per step, at
 * most, and the stop: no impulse moved by more than this times its cone's
 * radius in a sweep. Why 1e-6: the friction impulses are then converged far
 * below the step's own error (PD_COMPLIANT_E_TOL); sticking faces converge in
 * a few sweeps. 32 only stops a pathological coupling. */
#define PD_COMPLIANT_SWEEPS 32
#define PD_COMPLIANT_SWEEP_TOL 1e-6

/* Two contacts sticking are solved in closed form (compliant.c), a 3 x 3
 * Cholesky factorisation of their coupled inverse mass in the impulses
 * orthogonal to the squeeze; a pivot under this times the matrix's trace
 * means the two contacts are at one point of the floor's plane to
 * round-off (the matrix is then singular), and the sweeps take them. Why
 * 1e-9: well above round-off's 1e-16 times the trace, far below any two
 * hull vertices' pivot (of the order of their distance over the part's
 * size, squared). */
#define PD_COMPLIANT_PAIR_PIVOT_REL 1e-9

/* The closed form for two sticking contacts is tried only once a sweep
 * leaves both impulses within their cones without converging, or once
 * their sweeps have run this many without converging: most pairs slide
 * and their sweeps converge in 3 or 4 (a cube's or box's impacts), and
 * trying it at every pair's step cost 19-21% of the cube's and box's
 * compliant runs. Either way the motion is the same to the sweeps' own
 * tolerance (both stop the slips; they may share the free squeeze
 * differently); only the cost moves. */
#define PD_COMPLIANT_PAIR_AFTER 8

/* A contact below the floor is resting, not in the middle of a bounce,
 * when it moves either way no faster than resting contact arrives and its
 * spring holds at most this many times the part's weight. Why 4: a part
 * resting or rocking slowly on one vertex or an edge loads it with its
 * weight and the centripetal part of its rocking, well under 4 m g, while
 * a bounce at the resting speed v_rest already compresses its contact to
 * about that much, and every faster bounce to more; the test exists so that
 * a bounce's turning point (speed 0, deepest) is never taken for rest. */
#define PD_COMPLIANT_REST_LOAD 4.0

/* Steps between two tests of the outcome: the test costs a descent lookup,
 * tens of steps' work; deciding a few steps late changes nothing, since a
 * decided drop stays in its basin. */
#define PD_COMPLIANT_TEST_EVERY 8

/* The scaled law's integration, in its own units (time 1 / omega, the
 * contact lasting a few units): the first step tried, the horizon no contact
 * reaches (a stop only: the end is found on s = 0 long before), and the
 * classical RK4 substeps of the step in s that lands on s = 0 (the step is
 * at most a few hundredths in s, so 64 substeps leave its error far below
 * PD_COMPLIANT_LAW_TOL). Bisection on chi gives up above
 * PD_COMPLIANT_LAW_CHI_MAX (e is 0.01 at chi 100: no e in range needs it). */
#define PD_COMPLIANT_LAW_FIRST_STEP 1e-3
#define PD_COMPLIANT_LAW_HORIZON 1e3
#define PD_COMPLIANT_LAW_HENON_STEPS 64
#define PD_COMPLIANT_LAW_CHI_MAX 1e6

/* The first bracket of chi: (1 +- PD_COMPLIANT_LAW_CHI_SPREAD) times a
 * guess of chi e / (1 - e), times (1 - e) / e. chi e / (1 - e) is 1.010
 * at e = 0.01, 1.111 at 0.1, 1.323 at 0.3, 1.433 at 0.5, 1.481 at 0.7 and
 * 1.498 to 1.500 from 0.9 to 1 (chi goes as 1 / e towards 0 and as
 * 1.5 (1 - e) towards 1); the guess 1.5 - 0.5 (1 - e)^2.7 is within 1.2% of
 * it at every e (PD_COMPLIANT_LAW_CHI_GUESS the exponent), so a spread of
 * 3% holds the root. A table of laws brackets each node's within
 * PD_COMPLIANT_TABLE_SPREAD of the value extrapolated from the nodes below
 * (65 nodes over 0.01 to 1 move it by under 2% a node, the extrapolation's
 * error far less). Any bracket gives the same chi to PD_COMPLIANT_LAW_TOL
 * (one that misses the root is moved past it, by widths that double);
 * only the number of contacts integrated moves. */
#define PD_COMPLIANT_LAW_CHI_GUESS 2.7
#define PD_COMPLIANT_LAW_CHI_SPREAD 0.03
#define PD_COMPLIANT_TABLE_SPREAD 1e-3

#endif
