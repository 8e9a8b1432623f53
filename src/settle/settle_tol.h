/* settle_tol.h (private): tolerances of the test that decides a drop. The
 * rest fall it allows for, PD_TOL_REST_FALL_REL, is public
 * (posedrop/tolerances.h); conventions as there. */
#ifndef PD_SETTLE_TOL_H
#define PD_SETTLE_TOL_H

#include "posedrop/tolerances.h"

/* The drop's decision test looks up where quasi-static descent lands
 * (src/settle/descent_map.c) and answers only when gravity's direction lies
 * at least this angle inside the region that answer holds for; nearer a
 * boundary it runs the descent itself. Why 1e-9 rad: the walk's decisions
 * are computed with round-off of ~1e-16 (the map's margins are scaled by each
 * region's conditioning), so 1e-9 leaves seven orders between a looked-up
 * answer and one the walk could decide otherwise; a direction within 1e-9 of
 * a boundary is rare (a tilt at rest is ~1e-4, PD_TOL_REST_FALL_REL), so
 * nearly every lookup answers. Larger: more walks, no other effect; much
 * smaller: the map could answer where round-off flips the walk's answer. */
#define PD_TOL_DESCENT_MAP 1e-9

/* A part lying on a stable facet is settled when its rocking energy plus
 * the rest fall, times this, is below the barrier its nearest edge keeps
 * against friction and spin (src/settle/flat_rest.c). Why 2: a safety factor
 * on an argument that is not a proof; deciding at factor 1 instead of
 * running each drop to its energy test already changed no outcome in
 * thousands of cube, box, coin, cap and button drops (docs/validation.md,
 * "Deciding a drop early"). Larger: later decisions, more collisions;
 * smaller: less margin against a rocking part that friction could pump. */
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

#endif
