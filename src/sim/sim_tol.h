/* sim_tol.h (private): tolerances of the drop loops and of the pose chain of
 * --initial stationary. Conventions as in posedrop/tolerances.h. */
#ifndef PD_SIM_TOL_H
#define PD_SIM_TOL_H

/* A contact approaching slower than this times sqrt(g L) (the speed of
 * falling the part's own size) is resting, not colliding: the drop steps on
 * and lets it meet the floor again as a microcollision. Why 1e-9:
 * velocities after a resolved collision carry round-off of ~1e-16 of the
 * speeds involved (up to ~10 sqrt(g L) for the paper's drops), so 1e-9 is far
 * above it; a genuine impact after falling even the impact search's height
 * tolerance (1e-9 L) arrives at sqrt(2e-9) ~ 4e-5 sqrt(g L), far above the
 * threshold. Larger: slow genuine impacts would be ignored; smaller: a
 * contact just resolved would be "hit" again by its own round-off. */
#define PD_TOL_APPROACH_REL 1e-9

/* A stepping engine's drop ends only when the part lies on the facet of its
 * basin, tilted less than this from it (and its energy is below the basin's
 * barrier). Why 1 degree (0.0175 rad): soft contacts let a resting part sink
 * and rock by a fraction of a degree, so much less would wait for settling
 * that never comes; the energy test already rules out leaving the basin, and
 * 1 degree is far below any tilt at which a part could still be on its way
 * to another pose. */
#define PD_TOL_REST_TILT 0.0174532925199432958

/* Pseudo-drops spread evenly over the poses (those with drops started on
 * them) before each row of the transition matrix, and mu0, is redrawn for
 * the stationary intervals. Why: redrawn from the counts alone, a transition
 * no drop made never appears in a redraw, so a pose that kept every one of
 * its m drops is a trap in every redrawn chain and its long-run probability
 * gets an interval of zero width, although the data allow it to be left
 * with probability up to ~3/m. On known chains with m = 20 drops per row,
 * the nominal 95% intervals held the truth 47% of the time without
 * pseudo-drops on a chain with a pose kept 97% of the time, and 94-100% with
 * 0.5 on every chain tried; at m = 100, 92-98%. Half a drop is Jeffreys's
 * prior on "does it ever leave" (a Beta(1/2, 1/2) gives each outcome half a
 * pseudo-count). Larger: intervals widen everywhere for no gain in coverage
 * (1: 95-100% at m = 20); smaller: traps return. It moves only the intervals
 * (which are then stretched to hold p, markov.c); p is the long-run
 * distribution of the counts themselves. */
#define PD_STATIONARY_PSEUDO_DROPS 0.5

/* How far a rest step may let a vertex sink below the floor, times L. Why
 * 2e-4: resting contact falls PD_TOL_REST_FALL_REL (1e-4) per step by
 * design; a part that also turns must not carry another vertex much deeper
 * meanwhile, so that lasting contact stays within 1e-3 L of the floor
 * (docs/contact.md); at twice the rest fall the bound costs extra steps only
 * where the part turns or falls faster than 2 rest falls per rest step. */
#define PD_REST_SINK_REL 2e-4

/* The energy per unit weight, times L, that a rest step's return onto the
 * floor may add where the motion is too slow to pay for it (src/sim/drop.c:
 * the step is cut so that its turn carries no vertex deeper, beyond the
 * centre's fall, than the kinetic energy can lift back, or than this); the
 * impulse engine's outcome test allows for it (pd_settle.margin). Why 1e-8:
 * it must stay below the lowest barrier a part's basins are told apart by
 * (two stable facets meeting at a ridge of 0.1 degree: 3e-7 L on the
 * 2 x 1 x 1 roof box of the tests), and each order of magnitude smaller
 * shortens the slowest rest steps about threefold (the step goes as
 * sqrt(this) where the kinetic energy is this small). Larger: shallower
 * ridges rock until the time limit; smaller: more rest steps as a part
 * comes to rest. */
#define PD_REST_TURN_REL 1e-8

/* The automatic contact time (pd_contact_time_auto) grows with the size L,
 * so the static compression of a contact under the part's weight, g T^2 /
 * pi^2, grows as L^2: past 1.2 m it would exceed this share of L (a 10 m
 * part 1%, a 1000 m cube sinks deeper than its size, with every engine's
 * drops rocking in the floor until their time limit). The duration is
 * capped there. Why 1e-3: the depth lasting contact stays within
 * (docs/contact.md); a 30 m coin with 2.5% left 12 of 30 impulse drops
 * unsettled, with 0.3% none. Smaller: parts from a few tens of cm would
 * lose the Hertz duration the scene stands for. */
#define PD_CONTACT_AUTO_SINK_REL 1e-3

/* The most fixed steps a stepping engine's drop may need to reach its time
 * limit; a run that would need more is refused (pd_sim_run, PD_ERR_RANGE)
 * with the step and the limit that make it. Why 1e7: ODE and Bullet take 2
 * to 5 us a step on a small hull, so a drop that runs to its limit costs up
 * to a minute of CPU; a 1000 m cube's automatic limit (1345 s) at the
 * default steps takes 1.4e6. Larger: a run of giants on the default step
 * would take hours; smaller: the 1000 m cube would need a coarser step. */
#define PD_STEPS_MAX 1e7

/* The highest drop height, in sizes of the part, that a run accepts
 * (pd_sim_run refuses more with PD_ERR_RANGE, naming the ratio). Why 1e6:
 * the part lands at sqrt(2 h / L) times its own natural speed and bounces
 * for longer, in its own natural time, the higher that is, and a drop's
 * cost grows faster than in proportion to h / L (docs/limits.md gives the
 * measured cost per drop): at 1e6 one drop would take hours, and from about
 * 1e11 (a 1e-12 m part from 0.12 m) the collisions' searches fail outright.
 * The command warns from 100 sizes (a height or a part in the wrong unit).
 * Larger: runs that never end and internal failures instead of a clear
 * refusal; smaller: would refuse grains dropped from a metre. */
#define PD_HEIGHT_SIZES_MAX 1e6

/* The coarsest fixed step a stepping engine is given, the CLI's --dt limit:
 * a part of 1 cm dropped 0.12 m meets the floor at 1.5 m/s and crosses its
 * own size in under 7 ms, so a longer step would pass through contacts. */
#define PD_SIM_DT_MAX 0.01

/* --effect's next round asks for n (res / delta)^2 drops in all, res the
 * widest effect half-width at n drops: this factor more, because res is
 * itself estimated from the drops so far and a round sized on a lucky low
 * res would stop just short of delta and need another whole round. Why
 * 1.1: a bootstrap half-width from a few thousand drops is good to some
 * 5-10%; larger rounds overshoot the drops asked for. */
#define PD_EFFECT_ROUND_MARGIN 1.1

/* The most drops one --effect round may ask for, only so that the product
 * above fits a long; the run's own max_drops bounds it far lower. */
#define PD_EFFECT_ROUND_MAX 1e15

#endif
