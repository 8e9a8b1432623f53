/* engines_tol.h (private): the ODE and Bullet adapters' modelling constants.
 *
 * The stepping engines cross-check the impulse simulator. Their contacts are
 * soft (a penetration spring) and resolved once per fixed time step, so they
 * need guards the event-driven simulator does not. Lengths relative to the
 * part's size L, as in posedrop/tolerances.h. */
#ifndef PD_ENGINES_TOL_H
#define PD_ENGINES_TOL_H

/* ODE contact points: at most this many per step go to the solver. Three
 * already fix a resting facet; eight spread over the facet (chosen by farthest
 * point, deepest first) keep a many-cornered facet (a 32-gon coin) from being
 * held at one side only, at a cost of 24 constraint rows, which the dense
 * solver of dWorldStep handles in microseconds. */
#define PD_ODE_MAX_CONTACTS 8

/* ODE contacts approaching slower than this times sqrt(g L) do not bounce
 * (ODE's bounce_vel). Why: a resting contact is pressed into the floor by
 * gravity every step and meets it again at ~g dt plus the spring's
 * correction speed; with bounce on, a resting part would hop forever instead
 * of settling. 0.1 sqrt(g L) is the speed of a fall of L/200: a genuine
 * impact from any drop height of a few L arrives far above it (1 mm onto a
 * 1 cm part already gives 0.45 sqrt(g L)), while a contact at rest stays below
 * it for time steps up to 0.1 sqrt(L/g) (3 ms at L = 1 cm; the default is
 * 1 ms). Larger: slow genuine impacts lose their bounce. Smaller: jitter. */
#define PD_ODE_BOUNCE_VEL_REL 0.1

/* The floor's stiffness for ODE's soft contacts (soft_erp, soft_cfm): one
 * contact carrying the part's whole weight sinks this far (times L).
 * Why 1e-4: the same depth the impulse simulator lets a resting contact fall
 * (PD_TOL_REST_FALL_REL), so both engines read heights and tilts to the same
 * 1e-4; as a spring, the part bounces on it at sqrt(g / (1e-4 L)) rad/s,
 * 1.6 per ms at L = 3.7 cm: ODE's implicit contact step is stable at any
 * stiffness, and at this one a collision still spans a few steps of 1 ms.
 * Larger (1e-2 L): the part visibly sinks and tilts 0.6 deg on a rocking
 * vertex. Smaller: the spring stops being resolved by the time step and ERP
 * tends to 1, so penetration is pushed out in one step, which ODE's manual
 * warns adds energy. Scaling with m g / L makes the choice the same for a
 * 1 cm and a 1 m part. */
#define PD_ODE_SINK_REL 1e-4

/* Damping ratio of that contact spring: critical, so a contact settles
 * without ringing; the rebound is ODE's bounce (= restitution) alone, not a
 * spring oscillation on top. */
#define PD_ODE_DAMPING_RATIO 1.0

/* ODE's constraint force mixing on the rows without a cfm of their own:
 * the contacts' friction and drilling rows (ODE's world cfm, in ODE's
 * units, where masses and times are of order 1: see engine_ode.c). A row
 * with cfm c holds its velocity at -c times its force, so below mu N
 * friction is a damper of coefficient 1/c, and a slip relaxes over about
 * m_eff c instead of stopping. The contact spring's cfm, 1 / (h kp + kd),
 * which the world had until 2026-11-28, is a relaxation time of a
 * fraction of a millisecond for a centimetre part, of the order of an
 * impact: friction could not stop a slip within it (measured in
 * docs/engines-crosscheck.md). Why 1e-10 (ODE's own default): a slip then
 * relaxes in 1e-10 time units, far inside any step, while the LCP stays
 * regular where the kept contacts' rows are dependent (a face's eight
 * corners); with 0 the dense solver failed. */
#define PD_ODE_FRICTION_CFM 1e-10

/* A contact whose slip at the start of a step is faster than this many
 * steps of friction under the part's weight (mu g dt) slides through the
 * step: its friction acts along the slip alone (ODE: engine_ode.c, Bullet:
 * friction_directions in engine_bullet.cpp). A slower one (a contact
 * sticking, or starting to) keeps a second friction axis so that it does
 * not creep sideways. The bound shrinks with the step, so converged results
 * do not depend on it; an impact's larger normal force may stop a faster
 * slip within one step, and the single axis then stops it along the slip
 * (its row's limit is not reached), leaving the sideways drift of one
 * step. Why 10 and not 1 (the friction of a resting contact cannot stop a
 * faster slip within the step): at 1, four of 100 ODE drops of a 1 mm cube
 * spun at 3000 rad/s at the default 1 ms step ran to the time limit
 * (tests/unit/test_hard_parts.c); at 10 none did. Why that happens at 1
 * was not found. */
#define PD_ENGINE_SLIDE_STEPS 10.0

/* Bullet's collision margin, times the part's size L or its thickness if
 * that is less (a needle's margin at 1e-3 L was its whole thickness, and it
 * sank through the floor: 4 of 100 drops of a 1 m x 1 mm rod): its convex shapes are the hull inflated
 * by a sphere of this radius (Bullet's default, 0.04 m absolute, is four times
 * a 1 cm part). The adapter lowers the floor plane by the margin, so heights
 * against the floor are exact whatever its value; what it still moves is the
 * contact point, m below the true corner, so friction acts on a lever arm off
 * by m. Why 1e-3: that lever-arm error (1e-3 of the part's size) is far below
 * the uncertainty of mu itself, while the margin stays ~1e4 times above the
 * single-precision round-off of Bullet's coordinates (6e-8 L). Larger: friction
 * torques visibly wrong (1e-1 L is a tenth of the arm); smaller than ~1e-5:
 * within a few hundred ulps of float coordinates. */
#define PD_BULLET_MARGIN_REL 1e-3

/* The most of the part's thickness that the round-off of Bullet's float
 * coordinates at the drop's scale may be (see bullet_refuses); a part
 * above it is refused for Bullet. Why 1e-2: the contacts are then known to
 * a hundredth of the thickness, the resolution at which a face rest is
 * still told from an edge's; the measured parts at either side (1.4e-2
 * fails, 3.2e-3 works) are in engine_bullet.cpp. */
#define PD_BULLET_WIDTH_ULPS_MAX 1e-2

/* Bullet contacts approaching slower than this many steps of gravity (g dt) do
 * not bounce (Bullet's restitution velocity threshold, by default 0.2 m/s
 * absolute, which is 2/3 of the speed of falling a 1 cm part's own size). A
 * resting contact closes at g dt per step, the velocity one step of gravity
 * adds; restitution on it would make the part chatter on the floor. Why 2: it
 * stays clear of that resting speed (and of the solver's residue on it),
 * while a genuine bounce kept has fallen at least (2 g dt)^2 / 2g = 2 g dt^2,
 * 2e-5 m at the default 1/960 s. Larger: real low bounces are killed;
 * smaller: resting contacts chatter. */
#define PD_BULLET_BOUNCE_STEPS 2.0

/* RK4 steps per undamped half period (pi in scaled time) with which
 * pd_engine_hc_law integrates the scaled Hunt-Crossley contact for its
 * duration tau, the end found on the cubic through the last step's ends.
 * Why 256: RK4's error goes as the fourth power of the step and so does
 * the cubic's; at 256 tau is within 1e-8 of a 200000-step integration at
 * every restitution from PD_ENGINE_E_MIN to 1 (2e-5 at 64, 5e-7 at 128),
 * a hundredth of the 1e-6 to which test_law holds it against the impulse
 * simulator's rk8pd integration; the law then costs some thousand RK4
 * steps, where 20000 steps a half period and a linear crossing (its error
 * the square of the step) cost 90,000 each time an engine's material
 * changed, once per drop in runs whose drops draw their restitution. */
#define PD_ENGINE_HC_STEPS 256

/* The most undamped half periods pd_engine_hc_law integrates: the contact
 * lasts 4.6 of them at PD_ENGINE_E_MIN (tau = 14.31) and fewer at any
 * higher restitution, so the bound only stops a loop that would not end. */
#define PD_ENGINE_HC_HALF_PERIODS 64

/* Share of the backward-Euler spring the stepping engines' contact rows
 * keep. ODE and Bullet take a contact row's spring and damper as erp and
 * cfm, which give the force k d + b d' at the step's end rate d', with
 * b = h k + c for a spring stepped implicitly (their documented form) and
 * b = c for one taken at the step's start. The implicit spring loses a
 * share of the rebound of order omega h, first order in the step (at 20
 * steps a contact, 0.043 of the approach speed for e = 0.3, 0.19 for
 * e = 0.9); the spring at the step's start with the damper at its end
 * (semi-implicit Euler, as the impulse simulator's compliant step)
 * rebounds within 0.0016 of e at 20 steps and 0.0004 at 40, wherever in
 * the step the vertex touches (the scaled law stepped as the engines step
 * it, e 0.05 to 1: scripts/engine-step-rebound.py,
 * docs/engines-crosscheck.md). b = c alone would leave a row without
 * damping (c = 0 at e = 1 or at zero depth) an infinite cfm, so b keeps this share
 * of h k. Why 1e-3: its loss is that share of the implicit spring's, at
 * most 2e-4 of the approach speed at 20 steps, below the step's own error,
 * while cfm stays within 1e3 / (h k) and the rows of the solvers well
 * scaled. */
#define PD_ENGINE_SPRING_IMPLICIT 1e-3

#endif
