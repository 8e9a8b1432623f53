/* posedrop/tolerances.h: every numerical tolerance and input limit, in one place.
 *
 * Lengths are relative to the part's size L, the diagonal of the bounding box
 * of its (welded) vertices, so that scaling a part by 1e-3 or 1e3, moving it or
 * rotating it changes no decision the library takes. Absolute tolerances are
 * PD_TOL_..._REL * L. Probabilities are compared relatively. Angles are in
 * radians; comments give degrees.
 *
 * The values sit between two bounds that each comment names: above the
 * round-off of the computation they guard (a few 1e-16 relative for double
 * precision on the operations involved), and below the smallest genuine
 * feature the library must keep apart. */
#ifndef POSEDROP_TOLERANCES_H
#define POSEDROP_TOLERANCES_H

/* --- mesh input ------------------------------------------------------------ */

/* Vertices closer than this are one vertex (welding of triangle soups).
 * Why 1e-6: binary STL stores float32 (6e-8 relative) and many ASCII exporters
 * print six significant digits (up to 5e-7 relative), so the copies of one
 * vertex written by different triangles can differ by that much. Smaller: such
 * files stay open soups and are refused. Larger: would merge features of a
 * millionth of the part's size, far below anything manufactured. */
#define PD_TOL_WELD_REL 1e-6

/* --- convex hull ----------------------------------------------------------- */

/* Hull triangles whose vertices lie within this distance of a common plane are
 * merged into one polygonal facet, and a hull vertex that ends up on fewer than
 * three facets (a point on an edge) is dropped. Also the distance below which
 * input points count as coplanar or collinear (a sheet thinner than this has
 * no volume the hull can resolve).
 * Why 1e-7: the hull's triangles are exact, but the files are not. Binary STL
 * stores float32 (6e-8 relative) and CAD exporters print 6 to 9 digits, so the
 * four corners of a face that is flat in the designer's model scatter off one
 * plane by up to ~1e-7 L; shipped parts/cap.off (9 digits) splits its conical
 * faces at 1e-9. A face split by that noise becomes two facets, the centre of
 * mass lands on the crease as a knife edge, and a symmetric part's poses stop
 * being symmetric. Larger: on a tessellated curved surface, neighbouring
 * triangles within 1e-6 L of one plane already merge by the hundreds
 * (10^4 points on an ellipsoid); merging there changes no probability beyond
 * 1e-6, but it departs from the exact hull for no gain. Smaller: print noise
 * splits faces again. Facets meeting at 1e-7 rad merge (their poses differ by
 * less than any drop can show); at 1e-5 rad over a facet of size 0.1 L they
 * stay two. */
#define PD_TOL_PLANE_REL 1e-7

/* --- static estimators ----------------------------------------------------- */

/* The centre of mass must lie at least this far inside every hull facet
 * plane; closer is "on the hull" and the part is refused (it would balance on
 * a facet it touches with its own centre). Same bound as the plane tolerance:
 * the hull itself is only known to that accuracy. */
#define PD_TOL_COM_INSIDE_REL PD_TOL_PLANE_REL

/* Knife edge: the centre of mass projects within this distance of a facet's
 * boundary. Stability means "strictly inside", so such a facet is unstable and
 * a warning names it. Why 1e-11: the projection carries round-off of a few
 * 1e-16 L, from the centre of mass and the facet plane; the tests move the
 * centre 1e-9 L to either side of an edge and must see stable and unstable,
 * so the tolerance must stay well below 1e-9. */
#define PD_TOL_KNIFE_REL 1e-11

/* Two probabilities tie when they differ by at most this fraction of the larger.
 * Ties decide PQS transfers (a tie does not transfer, or a symmetric part would
 * lose its symmetry) and the order of poses (ties go by normal).
 * Why 1e-4: our own round-off is a few 1e-16, but the files are coarser. The
 * sides of a 32-gon prism, printed with 9, 7 (about float32) and 6 significant
 * digits, have solid angles spread by 6e-9, 1.0e-6 and 5.5e-6 relative
 * (measured). PQS's "strictly less probable" rule is discontinuous: a tie
 * below that spread hands a symmetric part an asymmetric answer decided by how
 * its file was printed (a band of a whole side jumps to its neighbour). 1e-4
 * leaves a margin of 18 over 6-digit files. Larger: genuinely different
 * facets would stop exchanging bands; but telling two probabilities of ~0.01
 * apart by 1e-4 relative takes ~1e10 drops, so no measurement can see it. */
#define PD_TOL_PROB_TIE_REL 1e-4

/* Unit normals whose components differ by at most this are equal when poses
 * that tie in probability are ordered by normal. Why 1e-9: computed normals
 * carry round-off of ~1e-16 per component, so a mirror-symmetric pair must not
 * be ordered by noise; distinct facets differ by 1e-7 rad or more (see
 * PD_TOL_PLANE_REL), two orders above. */
#define PD_TOL_NORMAL_TIE 1e-9

/* Quasi-static descent works on the unit sphere of gravity directions. An exit
 * point of a vertex region closer than this angle to a facet normal is snapped
 * to it; a descent step shorter than this is a knife edge.
 * Why 1e-12 rad (6e-11 deg): unit vectors carry round-off ~1e-16; facet normals
 * that must stay distinct differ by 1e-7 rad or more (see PD_TOL_PLANE_REL). */
#define PD_TOL_ANGLE 1e-12

/* The drop's decision test looks up where quasi-static descent lands
 * (src/settle/descent_map.c) and answers only when gravity's direction lies at least
 * this angle inside the region that answer holds for; nearer a boundary it
 * runs the descent itself. Why 1e-9 rad: the walk's decisions are computed
 * with round-off of ~1e-16 (the map's margins are scaled by each region's
 * conditioning), so 1e-9 leaves seven orders between a looked-up answer and
 * one the walk could decide otherwise; a direction within 1e-9 of a boundary
 * is rare (a tilt at rest is ~1e-4, PD_TOL_REST_FALL_REL), so nearly every
 * lookup answers. Larger: more walks, no other effect; much smaller: the map
 * could answer where round-off flips the walk's answer. */
#define PD_TOL_DESCENT_MAP 1e-9

/* Descent must lower the centre of mass along every quasi-static link. A rise
 * smaller than this (relative to L) is accepted as error of the facet planes;
 * a larger one is reported as PD_ERR_INTERNAL. Why 2 PD_TOL_PLANE_REL: a
 * merged facet's plane is fitted to vertices up to PD_TOL_PLANE_REL L off it
 * (hull_merge.c), so its height is known only to that, and a link between two
 * such facets may seem to rise by the sum. Measured: a hexagonal prism whose
 * points carry 1e-5 L of noise has a link between cap facets 2e-11 m apart in
 * height the wrong way (9e-9 L), which 1e-12 L reported as an internal error.
 * Larger: would hide a genuine descent bug; smaller: noisy parts fail. */
#define PD_TOL_HEIGHT_REL (2.0 * PD_TOL_PLANE_REL)

/* Exact PQS band: relative accuracy asked of the adaptive quadrature of the
 * band area. Why 1e-10: well below the 1e-9 tie tolerance that decides
 * transfers, above what GSL's 21-point rule reaches on smooth integrands. */
#define PD_TOL_BAND_QUAD_REL 1e-10

/* Pose classes (src/symmetry/symmetry.c): a rotation about the centre of mass maps the
 * hull onto itself when every vertex lands within this distance (times L) of
 * a vertex; the candidate rotations are found by matching distances from the
 * centre and between two reference vertices to the same accuracy, and two
 * poses of one class must rest at heights this close. Why 1e-5: a symmetric
 * part read from a file carries the file's print noise, up to 5e-7 L per
 * coordinate for 6 significant digits (see PD_TOL_PROB_TIE_REL), and its
 * computed centre of mass a similar amount; distances between two such points
 * and the rotation they define add a few of these, and a reference pair that
 * is close to collinear with the centre amplifies them a few times more: 1e-5
 * leaves a margin of ~5 over that. A genuine asymmetry of 1e-5 L (1 um on a
 * 10 cm part) is below what is manufactured or what any drop could tell
 * apart. Larger: features that differ by a hundredth of a millimetre would be
 * merged as symmetric. Smaller: 6-digit files of symmetric parts would lose
 * their symmetry. */
#define PD_TOL_SYMMETRY_REL 1e-5

/* --- output ----------------------------------------------------------------- */

/* Printed unit-normal components and probabilities smaller than this in
 * magnitude are written as 0: an axis-aligned normal carries round-off
 * components of ~1e-17 and they would print as noise (or as -0). 1e-12 is far
 * below any printed digit that matters (10 significant digits are printed). */
#define PD_PRINT_ZERO 1e-12

/* --- mass properties --------------------------------------------------------- */

/* A closed mesh whose enclosed volume is at most this times L^3 has no volume
 * (a flat or doubled surface, or one whose faces point inwards) and is refused
 * by pd_mass_compute. Why 1e-12: the volume is a sum of signed tetrahedra taken
 * from a point of the part, each with round-off of a few 1e-16 of its own
 * size, so a flat surface of area A comes out at ~1e-16 A L; even a finely
 * folded surface of a thousand L^2 stays below 1e-13 L^3. A genuine part of
 * size L has at least one extent much larger than 1e-12 L (a sheet 1 um thick
 * over a 1 m outline is 1e-6 L^3). Larger: thin but real plates and shims
 * would be refused. Smaller: round-off of a flat surface could pass as a
 * volume and give a centre of mass and inertia that are pure noise. */
#define PD_TOL_VOLUME_REL 1e-12

/* pd_mesh_orient decides whether one connected shell lies inside another by
 * the winding number of the other shell at a point of the first: 1 inside, 0
 * outside, exact integers up to round-off of a few 1e-16 per triangle. A point
 * that lies on the other shell (shells touching along a face) sees 1/2. A
 * winding number farther than this from every integer is such a touching
 * point, and another point of the shell is tried. Why 0.25: halfway between
 * the integer a clean point gives and the 1/2 a touching point gives, so
 * neither round-off (tiny) nor a touch (exactly 1/2) is mistaken for the
 * other. */
#define PD_TOL_WINDING 0.25

/* --- dynamics --------------------------------------------------------------- */

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
 * cancellation: GSL's forms, handed m alone, erred there by up to 0.1 rad
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

/* The lowest vertex (pd_body_support, src/dynamics/body.c) is found by hill-climbing
 * the hull's edges, then checking the other corners of the facets around it,
 * since a facet bent by up to PD_TOL_PLANE_REL can hide a lower corner behind
 * a diagonal. The check is skipped at a vertex whose facets all keep every
 * corner within this distance (times L) of the plane through the vertex and
 * its two neighbours on the facet, and inside their angle: no corner can then
 * lie lower than the vertex by more than this. Further corners can, by this
 * times a factor of the facets' shape: 22 measured on a 32-gon's cap bent on
 * purpose (3e-8 L of bend left the climb 7e-7 L high without the check).
 * Why 1e-13: exactly planar faces (a file's equal coordinates) come out of
 * the principal-axes rotation bent by round-off, measured at most 6e-18 L on
 * a 32-gon coin's caps and 4e-17 L on the shipped parts' flat faces, over
 * 2000 times below; a face whose file prints 12 digits is bent by up to
 * 1e-12 L and keeps its check. The height the impact search reads is then
 * at most ~2e-12 L above the true lowest on such a cap, 400 times below
 * PD_TOL_IMPACT_REL. Larger: a slightly bent face could hand the search a
 * height off by a visible part of its tolerance. Smaller: round-off on faces
 * of many corners (where it grows with the corners' count) would bring the
 * check back where it cannot change the answer. */
#define PD_TOL_SUPPORT_FLAT_REL 1e-13

/* At impact, every hull vertex within this height of the floor belongs to the
 * contact set handed to the (multi-contact) collision resolver. Why 1e-6: a
 * face landing flat touches with all its corners at once, and a face landing
 * within 1e-6 rad (6e-5 deg) of flat is resolved as flat, instead of as a
 * cascade of micro-collisions a few 1e-7 s apart that each cost a search.
 * Must stay above PD_TOL_IMPACT_REL (the lowest vertex itself may sit that
 * high). Larger (1e-4, i.e. 0.006 deg): corners genuinely apart would be
 * struck together and the bounce would change. Smaller: the cascade above. */
#define PD_TOL_CONTACT_REL 1e-6

/* Conservative-advancement steps one impact search may take before it reports
 * PD_ERR_NO_CONVERGENCE. Each step closes at least the fraction
 * (true approach speed)/(speed bound) of the remaining gap; a part whose
 * rotation bound exceeds its approach speed a hundredfold needs ~100 ln(1e9)
 * ~ 2000 steps to converge to PD_TOL_IMPACT_REL. 100000 is far above any
 * genuine search and still stops a runaway (NaN-free but stuck) state fast. */
#define PD_CONTACT_MAX_STEPS 100000

/* A contact approaching slower than this times sqrt(g L) (the speed of
 * falling the part's own size) is resting, not colliding: the drop lets it
 * fall the contact tolerance and meet the floor as a microcollision. Why
 * 1e-9: velocities after a resolved collision carry round-off of ~1e-16 of
 * the speeds involved (up to ~10 sqrt(g L) for the paper's drops), so 1e-9
 * is far above it; a genuine impact after falling even PD_TOL_IMPACT_REL * L
 * arrives at sqrt(2e-9) ~ 4e-5 sqrt(g L), far above the threshold. Larger:
 * slow genuine impacts would be ignored; smaller: a contact just resolved
 * would be "hit" again by its own round-off. */
#define PD_TOL_APPROACH_REL 1e-9

/* Resting contact is simulated as microcollisions: a vertex pressed on the
 * floor falls this far (times L), meets it at the speed of that fall and is
 * stopped dead (e = 0: a resting contact does not bounce, and the Zeno cascade
 * of ever smaller bounces that e > 0 would start is skipped). Why 1e-4: the
 * cost of rolling and rocking contact is one collision per fall, so it scales
 * as 1/sqrt(this) (1e-6 made a 32-gon cap take 5000 collisions a drop); the
 * energy test adds this depth to the energy. Caveat, measured: each step is
 * stopped where it ended, so sustained contact sinks about this much per
 * step (mean depth at collisions 1-2e-3 L, maximum 2-6e-2 L with spin), and
 * stopping the fall damps the motion artificially; with the contact phases
 * taking vertex and edge contact, the cap's pose 3 reads 39.0, 45.7, 48.9,
 * 49.9% at 1e-3, 3e-4, 1e-4, 1e-5 (README: "Known limit"). Larger: more
 * damping and sinking; smaller: slower for a point or less. */
#define PD_TOL_REST_FALL_REL 1e-4

/* A part lying on a stable facet is settled when its rocking energy plus
 * the rest fall, times this, is below the barrier its nearest edge keeps
 * against friction and spin (src/settle/flat_rest.c). Why 2: a safety factor on an
 * argument that is not a proof; measured, deciding at factor 1 instead of
 * running each drop to its energy test changed no outcome in 2000 cube
 * drops (and 1000 each of box, coin, cap and button drops at 2), while the
 * cube's collisions per drop fell from 43 to 11 (12 at 2). Larger: later
 * decisions, more collisions; smaller: less margin against a rocking part
 * that friction could pump. */
#define PD_FLAT_SAFETY 2.0

/* pd_flat_settled first compares a lower bound of the rocking energy (the
 * centre of mass's height above lying flat, without the lowest corner's
 * pass) with the barrier, and refuses when the bound exceeds it by more
 * than this share of PD_FLAT_SAFETY. Why 0.99: the bound and the exact sum
 * round differently, by ~1e-16 of the part's size, against which the
 * margin of 1% of PD_FLAT_SAFETY times the rest fall (~1e-4 L) is 10^10
 * times larger, so the early refusal never refuses what the exact test
 * takes (trial records byte-identical with and without it). Nearer 1: no
 * gain; smaller: fewer early refusals. */
#define PD_FLAT_EARLY_SHARE 0.99

/* --- sliding contact phases (src/contact/contact_phase.c) --------------------------- *
 * One vertex or edge sliding on the floor is integrated as an ODE in units
 * of the part: length L, time sqrt(L/g), speed sqrt(g L). */

/* Local error per step asked of the phase's integrator (rkck), absolute and
 * relative in those units. Why 1e-8: what matters is the error a whole phase
 * leaves, against the rest-fall margin (1e-4 L) the energy test allows for.
 * Measured (300 drops, seed 3, every phase integrated again over the same
 * time by rk8pd at 1e-14): at most 5e-8 in the state (L, sqrt(g L)) and
 * 2e-7 in the rate of turn (per sqrt(L/g)); the energy off by at most
 * 1.4e-8 m g L per phase (cube 0.8e-8, box 1.4e-8, coin 0.9e-8). Even the
 * coin's 16 phases per drop, all erring upwards, stay ~400x inside the
 * margin; sticking phases, which conserve energy, drift by the same 1e-8.
 * Larger: that margin shrinks in step (the error grows as about tol). Smaller:
 * costs steps, ~tol^(-1/5): 1e-9 (errors 1.4e-9 m g L) takes 1.3x the
 * instructions per phase, 1e-10 1.8x; rk8pd at 1e-10 (errors 5e-12) 1.7x. */
#define PD_TOL_PHASE_ODE_REL 1e-8

/* A phase starts from microcollision chatter by projecting the velocities
 * onto the contact constraints, an inelastic impulse; it is admitted only if
 * it takes at most this times m g L of kinetic energy. Why 1e-5: a tenth of
 * what the microcollision it replaces takes (a contact stopped from the
 * speed of a rest fall loses about m g rest_fall = 1e-4 m g L), so entering
 * damps less than going on. Measured on the paper's cap (4000 drops): its
 * pose classes read the same at 1e-7, 1e-5 and 1e-4 (pose 3 48.9%), while
 * the cube's collisions per drop fall from 63 at 1e-7 to 43 at 1e-5; a first
 * version with no limit at all damped the cap to 38.5%. Larger: towards that
 * damping; smaller: fewer phases, more microcollisions. */
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

/* --- collisions (src/impact*.c) --------------------------------------------- *
 * A collision is solved in units where |u0| = 1 (u0 the pre-impact contact
 * velocity) and K's mean diagonal is 1, so these are relative to |u0| and the
 * law stays homogeneous: scaling u0, the masses or the part changes no
 * decision taken here. */

/* Local error per step asked of the sliding ODE (eq. 14 of the paper), both
 * absolute (in units of |u0|/K and |u0|^2/K) and relative. Why 1e-9: rk8pd's
 * error estimate is far above its error here, and the event tolerance, not
 * this, sets a collision's accuracy. Measured on 9e4 impacts recorded from
 * drops (cube both laws, box, coin, cap) and 4e4 random ones, against a
 * reference at 1e-13 with events at 1e-12: the impulse's median error is
 * 1e-13 at 1e-9 (2e-14 at 1e-11), its 99th percentile and maximum ~1e-10
 * and ~5e-10 at both (the events'), so 1e-9 is no further from the
 * reference than 1e-11 was; 1e-8 doubles the maximum (2.8e-9 on the coin).
 * The energetic law's bookkeeping (e = 1, mu < 1e-3, 2e4 impacts) moves
 * dke by 5e-11 |p| |u0|, 200 times below PD_TOL_IMPACT_ENERGY_REL;
 * homogeneity holds to 5e-13; outcomes (stuck, stable, resumed) differ from
 * the reference in 499 of 1.3e5 impacts, 528 at 1e-11 (the events' share).
 * It costs 30% fewer steps than 1e-11 (1e-10: 17%). Larger: the error grows
 * past the events'. Smaller: steps for nothing; below ~1e-13 the controller
 * chases round-off of p (1e-16 times the condition number of K, up to 1e6). */
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
 * the measured one, ~1e-13 (PD_TOL_IMPACT_ODE_REL's comment), not the
 * integrator's requested tolerance. Larger: a part declared stuck at 1e-6
 * |u0| keeps that slip in its state and the impulse carries a 1e-6 relative
 * error. Smaller: near the integration error, its noise would decide whether
 * a near-miss of the origin sticks. */
#define PD_TOL_IMPACT_EVENT_REL 1e-9

/* Largest number of integrator steps (accepted or refused for an event) one
 * collision may take before PD_ERR_NO_CONVERGENCE. Why 1000: at the ODE
 * tolerance above, collisions recorded from drops take 5-12 steps on average
 * and random impacts at most ~30 (test_impact.c), since a stable stick
 * approached along a slowly closing invariant ray (stiff for an explicit
 * integrator; it once took up to 388 steps and 1 impact in 1e5, or 1 in 1e4
 * microcollisions of the paper's cap, exceeded 1000) is snapped onto that
 * ray or finished along it in closed form (impact_slide.c). 1000 bounds the
 * cost of a collision to ~1 ms and still stops a runaway; the drop then
 * resolves it by a counted fallback. */
#define PD_IMPACT_MAX_STEPS 1000

/* The slide's tail onto an incoming ray, a power series in the angle to the
 * ray (impact_ray_series.c), is built and tried within this angle (rad) of
 * it; it is used only where its own truncation estimate is below
 * PD_TOL_IMPACT_TAIL_REL (|u0|/K, the impulse's unit) and the angle within
 * half its radius of convergence, so the angle bounds the cost, not the
 * error. Why 1: measured on the recorded drops and 4e4 random impacts, 1
 * took 1-7% fewer steps than 0.5 and the fewest instructions (0.5: 0.5-1%
 * more); the impulses' maximum error against the tight reference was the
 * same at both. Larger: past the radius of most rays' series (the nearest
 * other invariant ray), builds for nothing; smaller: slides integrated
 * further, and below ~0.1 the slide costs what it did with the
 * third-order tail this replaced. */
#define PD_TOL_IMPACT_SERIES_ANGLE 1.0

/* The ray tail's series is used only when its error estimate is at most
 * this, relative to |u0| like the event tolerance. Why a tenth of
 * PD_TOL_IMPACT_EVENT_REL: sticking is declared at that slip anyway, so the
 * tail then adds no error the event location does not already allow.
 * Larger: the tail's error would show beside the events'; smaller: more
 * slides integrated to the end, no change in results. */
#define PD_TOL_IMPACT_TAIL_REL (0.1 * PD_TOL_IMPACT_EVENT_REL)

/* A collision "added energy" when its kinetic energy change p.(u0 + u1)/2
 * exceeds this fraction of |p| |u0| (the size of the work terms it is a sum
 * of). Why 1e-8: the energetic law's own bookkeeping error is the ODE's
 * (measured <= 5e-11); Poisson's genuine gains in 3-D are percent-level. Larger would
 * hide small genuine gains, smaller would flag integration noise. */
#define PD_TOL_IMPACT_ENERGY_REL 1e-8

/* K must be symmetric to this fraction of its largest entry: it is assembled
 * from products of exact quantities, so asymmetry beyond round-off (1e-16)
 * means a caller's bug, e.g. a transposed inertia. */
#define PD_TOL_IMPACT_K_SYM_REL 1e-12

/* --- engines (src/engines/engine_ode.c, src/engines/engine_bullet.cpp, src/sim/drop_step.c) -- *
 * The stepping engines that cross-check the impulse simulator. Their contacts
 * are soft (a penetration spring) and resolved once per fixed time step, so
 * they need guards the event-driven simulator does not. */

/* A stepping engine's drop ends only when the part lies on the facet of its
 * basin, tilted less than this from it (and its energy is below the basin's
 * barrier). Why 1 degree (0.0175 rad): soft contacts let a resting part sink
 * and rock by a fraction of a degree, so much less would wait for settling
 * that never comes; the energy test already rules out leaving the basin, and
 * 1 degree is far below any tilt at which a part could still be on its way
 * to another pose. */
#define PD_TOL_REST_TILT 0.0174532925199432958

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

/* Bullet's collision margin, times L: its convex shapes are the hull inflated
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

/* --- initial stationary (src/sim/montecarlo.c, src/sim/markov.c) ----------------- */

/* Fewest drops started resting on each stable pose. Each row of the
 * estimated transition matrix rests on this many drops, and a transition the
 * drops never show is taken to be impossible: one of probability 0.2 is
 * missed with probability 0.8^m, 11% at m = 10 and 33% at m = 5, and a missed
 * transition can split the chain into closed classes that do not exist
 * (wrongly trapping the long-run mass). Below 10 a row is little more than a
 * guess; larger would refuse -n 2000 on parts of more than ~200 stable poses
 * (the paper's insulator cap has 98, so it gets 20 drops per pose). */
#define PD_STATIONARY_MIN_POSE_DROPS 10

/* Redrawn chains behind each stationary 95% interval (a percentile
 * interval: its ends are the 2.5% and 97.5% points of the redrawn long-run
 * probabilities). Why 1000: the usual minimum for percentile intervals
 * (Efron and Tibshirani 1993, ch. 13); each end then sits on ~25 draws, and
 * for a normal spread its own Monte Carlo error is 0.085 standard errors,
 * 4% of the interval's half-width. More costs time linearly: each redraw
 * solves the chain, O(k^3) for k poses. */
#define PD_STATIONARY_RESAMPLES 1000

/* Pseudo-drops spread evenly over the poses (those with drops started on
 * them) before each row of the transition matrix, and mu0, is redrawn for
 * the stationary intervals. Why: redrawn from the counts alone, a transition
 * no drop made never appears in a redraw, so a pose that kept every one of
 * its m drops is a trap in every redrawn chain and its long-run probability
 * gets an interval of zero width, although the data allow it to be left
 * with probability up to ~3/m. Measured on known chains with m = 20 drops
 * per row (400 repetitions each): a pose kept 97% of the time, coverage of
 * the nominal 95% intervals 47% without pseudo-drops, 98% with 0.5, 98%
 * with 1; a sparse 5-pose chain 65-90% without, 94-100% with 0.5; a dense
 * one 93-95% either way; at m = 100, 0.5 gives 92-98% everywhere. Half a
 * drop is Jeffreys's prior on "does it ever leave" (a Beta(1/2, 1/2) gives
 * each outcome half a pseudo-count). Larger: intervals widen everywhere for
 * no gain in coverage (1: 95-100% at m = 20); smaller: traps return. It
 * moves only the intervals (which are then stretched to hold p, markov.c);
 * p is the long-run distribution of the counts themselves. */
#define PD_STATIONARY_PSEUDO_DROPS 0.5

/* --- limits ---------------------------------------------------------------- */

/* Largest vertex or face count a file may declare. Counts are also checked
 * against the bytes left in the file before any allocation, so a lying header
 * fails with a parse error, not an out-of-memory. 2^26 = 67M elements is ten
 * times the largest CAD meshes users feed to a pose estimator. */
#define PD_MAX_ELEMENTS (1 << 26)

/* The symmetry search tries every image of a reference pair of hull vertices
 * among the vertices at the same distances from the centre of mass: |A| x |B|
 * pairs, and checks each pair that also matches their distance apart on all
 * vertices. Past this many pairs the search is skipped with a warning and the
 * poses are not grouped (only the identity). The worst case within the limit
 * is a regular polygon prism, all of whose vertices sit at one radius: a
 * 4000-gon (8000 vertices, 6.4e7 pairs, 8000 rotations each checked on every
 * vertex) takes 5 s for the rotations and 7.5 s for the pose classes on this
 * project's machine (2026-11-23), and the cost grows as the square of the
 * vertex count; an asymmetric 8000-vertex sphere, also at one radius, takes
 * 0.3 s. Larger: the search could run for minutes on a finely tessellated
 * body of revolution. Smaller: such parts of a few thousand vertices would
 * lose their grouping for no need. */
#define PD_SYMMETRY_MAX_PAIRS (1L << 26)

/* Largest polygon a mesh face may have (vertex count of one OFF/OBJ face). */
#define PD_MAX_FACE_VERTICES 65536

#endif
