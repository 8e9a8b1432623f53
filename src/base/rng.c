/* rng.c: per-drop random streams (see rng.h). */
#include <math.h>
#include "base/rng.h"

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

void pd_rng_init(pd_rng *r, uint64_t seed, uint64_t stream)
{
    /* Mix the stream index through splitmix64 once before combining, so
     * that seeds S and drops i, i+1 land on unrelated states. */
    uint64_t x = stream;
    uint64_t h = splitmix64(&x) ^ seed;
    for (int i = 0; i < 4; i++)
        r->s[i] = splitmix64(&h);
}

uint64_t pd_rng_u64(pd_rng *r)
{
    uint64_t *s = r->s, result = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double pd_rng_uniform(pd_rng *r) { return (double)(pd_rng_u64(r) >> 11) * 0x1.0p-53; }

pd_vec3 pd_rng_unit_vector(pd_rng *r)
{
    /* Archimedes: uniform height and azimuth give a uniform point. */
    double z = 2.0 * pd_rng_uniform(r) - 1.0, phi = 2.0 * M_PI * pd_rng_uniform(r);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    pd_vec3 v = {s * cos(phi), s * sin(phi), z};
    return v;
}

void pd_rng_quaternion(pd_rng *r, double q[4])
{
    /* Shoemake (1992): three uniforms give a uniform unit quaternion. */
    double u1 = pd_rng_uniform(r), u2 = 2.0 * M_PI * pd_rng_uniform(r),
           u3 = 2.0 * M_PI * pd_rng_uniform(r);
    double a = sqrt(1.0 - u1), b = sqrt(u1);
    q[0] = a * sin(u2);
    q[1] = a * cos(u2);
    q[2] = b * sin(u3);
    q[3] = b * cos(u3);
}
