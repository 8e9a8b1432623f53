/* hash.h (private): 64-bit fingerprints of what an object was computed
 * from, so that a call given two objects can tell whether they belong
 * together (a static result and its part, a shard and its run).
 *
 * Not cryptographic: it guards against mistakes, not against forgery. Each
 * word goes through splitmix64's finaliser before it is folded in, so that
 * a change of one bit anywhere changes about half of the result's bits; two
 * different objects collide with probability about 2^-64. */
#ifndef PD_HASH_H
#define PD_HASH_H

#include <stdint.h>
#include <string.h>

typedef struct {
    uint64_t h;
} pd_hash;

static inline uint64_t pd_hash_mix(uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static inline void pd_hash_init(pd_hash *s, uint64_t kind)
{
    s->h = pd_hash_mix(kind ^ 0x9e3779b97f4a7c15ULL);
}

static inline void pd_hash_u64(pd_hash *s, uint64_t w)
{
    s->h = pd_hash_mix(s->h + 0x9e3779b97f4a7c15ULL) ^ pd_hash_mix(w);
}

/* By bits: the same computation gives the same bits, and -0 differs from 0. */
static inline void pd_hash_doubles(pd_hash *s, const double *x, long n)
{
    for (long i = 0; i < n; i++) {
        uint64_t w;
        memcpy(&w, &x[i], sizeof w);
        pd_hash_u64(s, w);
    }
}

static inline void pd_hash_ints(pd_hash *s, const int *x, long n)
{
    for (long i = 0; i < n; i++)
        pd_hash_u64(s, (uint64_t)(int64_t)x[i]);
}

#endif
