/* rng.h (private): one random stream per drop.
 *
 * xoshiro256** (Blackman and Vigna 2018): fast, 256 bits of state, passes
 * BigCrush. Drop i of a run with seed S gets the state produced by
 * splitmix64 from a hash of (S, i), so any drop can be replayed alone and the
 * run's results do not depend on which thread ran which drop. */
#ifndef PD_RNG_H
#define PD_RNG_H

#include <stdint.h>
#include "posedrop/types.h"

typedef struct pd_rng {
    uint64_t s[4];
} pd_rng;

/* The stream of drop `stream` in a run seeded with `seed`. */
void pd_rng_init(pd_rng *r, uint64_t seed, uint64_t stream);
uint64_t pd_rng_u64(pd_rng *r);
/* Uniform in [0, 1), 53 random bits. */
double pd_rng_uniform(pd_rng *r);
/* Uniform on the unit sphere. */
pd_vec3 pd_rng_unit_vector(pd_rng *r);
/* Uniform unit quaternion (w, x, y, z): a rotation uniform over SO(3). */
void pd_rng_quaternion(pd_rng *r, double q[4]);

#endif
