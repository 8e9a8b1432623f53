/* test_rng.c: per-drop random streams: reproducible, independent, uniform. */
#include "check.h"
#include "base/rng.h"
#include "suites.h"
#include "base/vec3.h"

void suite_rng(void)
{
    /* Same (seed, stream): same numbers; a neighbouring stream or seed:
     * different ones. */
    pd_rng a, b, c, d;
    pd_rng_init(&a, 42, 7);
    pd_rng_init(&b, 42, 7);
    pd_rng_init(&c, 42, 8);
    pd_rng_init(&d, 43, 7);
    int same = 1, diff_stream = 0, diff_seed = 0;
    for (int i = 0; i < 100; i++) {
        uint64_t x = pd_rng_u64(&a);
        same &= x == pd_rng_u64(&b);
        diff_stream += x != pd_rng_u64(&c);
        diff_seed += x != pd_rng_u64(&d);
    }
    CHECK(same);
    CHECK_INT(diff_stream, 100);
    CHECK_INT(diff_seed, 100);

    /* Moments of 1e6 draws, within 5 standard errors (a false alarm once in
     * 1.7 million runs). */
    enum { N = 1000000 };
    pd_rng r;
    pd_rng_init(&r, 1, 0);
    double s1 = 0, s2 = 0, lo = 1, hi = 0;
    pd_vec3 m = v3(0, 0, 0);
    double qw2 = 0, qn = 0;
    for (int i = 0; i < N; i++) {
        double u = pd_rng_uniform(&r);
        s1 += u;
        s2 += u * u;
        lo = fmin(lo, u);
        hi = fmax(hi, u);
    }
    CHECK(lo >= 0.0 && hi < 1.0);
    CHECK_NEAR(s1 / N, 0.5, 5 * sqrt(1.0 / 12 / N), "5 sigma of the mean of 1e6 uniforms");
    CHECK_NEAR(s2 / N, 1.0 / 3, 5 * sqrt(4.0 / 45 / N), "5 sigma of the mean square");
    for (int i = 0; i < N / 10; i++) {
        pd_vec3 v = pd_rng_unit_vector(&r);
        m = v3_add(m, v);
        double q[4];
        pd_rng_quaternion(&r, q);
        qn = fmax(qn, fabs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1));
        qw2 += q[0] * q[0];
    }
    /* Each component of a uniform unit vector has variance 1/3; each squared
     * component of a uniform unit quaternion has mean 1/4, variance 1/48
     * (a Beta(1/2, 3/2) variable). */
    CHECK_NEAR(v3_norm(m) / (N / 10), 0.0, 5 * sqrt(3.0 / 3 / (N / 10)), "5 sigma");
    CHECK_NEAR(qn, 0.0, 1e-15, "unit norm, round-off");
    CHECK_NEAR(qw2 / (N / 10), 0.25, 5 * sqrt(1.0 / 48 / (N / 10)), "5 sigma");
}
