/* test_stats.c: Wilson intervals and the corrected sample-size bound. */
#include <limits.h>
#include "check.h"
#include "base/stats.h"
#include "suites.h"

void suite_stats(void)
{
    /* The figures of docs/readings.md, "Sample size, eq. 17": eq. (17) with
     * the square restored. */
    CHECK_INT(pd_sample_size(0.05, 0.05, 1), 385);
    CHECK_INT(pd_sample_size(0.05, 0.10, 1), 271);
    CHECK_INT(pd_sample_size(0.05, 0.05, 4), 624);
    CHECK_INT(pd_sample_size(0.05, 0.05, 12), 821);
    /* Beyond what a long counts (1e45 drops for 1e-22; the api fuzz target
     * found the conversion undefined): the largest long. */
    CHECK(pd_sample_size(1e-22, 0.05, 3) == LONG_MAX);
    CHECK(pd_sample_size(1e-300, 0.05, 3) == LONG_MAX);

    /* Closed form: k = 0 of n = 10 at z = 1.96 gives [0, z^2 / (n + z^2)]. */
    double lo, hi, z = 1.959963984540054;
    pd_wilson(0, 10, z, &lo, &hi);
    CHECK_NEAR(lo, 0.0, 1e-16, "closed form");
    CHECK_REL(hi, z * z / (10 + z * z), 1e-14, "closed form, round-off");
    /* Symmetry: k of n mirrors n - k of n. */
    double lo2, hi2;
    pd_wilson(3, 17, z, &lo, &hi);
    pd_wilson(14, 17, z, &lo2, &hi2);
    CHECK_NEAR(lo, 1 - hi2, 1e-15, "symmetry, round-off");
    CHECK_NEAR(hi, 1 - lo2, 1e-15, "symmetry, round-off");
    pd_wilson(0, 0, z, &lo, &hi);
    CHECK(lo == 0.0 && hi == 1.0);
    /* No drop in a pose: p = 0 is the interval's lower end, exactly (it used
     * to come out as round-off like 5.55e-17, leaving p outside its own
     * interval); every drop in it: p = 1 is the upper end. */
    int exact_ends = 1;
    for (long n = 1; n <= 5000; n++) {
        pd_wilson(0, n, z, &lo, &hi);
        exact_ends &= lo == 0.0;
        pd_wilson(n, n, z, &lo, &hi);
        exact_ends &= hi == 1.0;
    }
    CHECK(exact_ends);

    /* The interval's ends are the roots of its defining quadratic,
     * (k/n - p)^2 = z^2 p (1 - p) / n, for every k of n (away from the
     * clamps at 0 and 1). */
    double worst = 0;
    for (long n = 1; n <= 60; n += 7)
        for (long k = 1; k < n; k++) {
            pd_wilson(k, n, z, &lo, &hi);
            double ph = (double)k / n;
            worst = fmax(worst, fabs((ph - lo) * (ph - lo) - z * z * lo * (1 - lo) / n));
            worst = fmax(worst, fabs((ph - hi) * (ph - hi) - z * z * hi * (1 - hi) / n));
        }
    CHECK_NEAR(worst, 0.0, 1e-15, "roots of the defining quadratic, round-off");

    /* Exact coverage at n = 100 (binomial sums) stays within 0.92..0.98 of
     * the nominal 0.95, as Brown, Cai and DasGupta (2001) report for
     * Wilson's interval; at p = 0.03 and 0.3 it is 0.9688 and 0.9372. */
    const double ps[] = {0.03, 0.1, 0.3, 0.5};
    for (int t = 0; t < 4; t++) {
        double cov = 0, pk = pow(1 - ps[t], 100); /* P(k = 0) */
        for (long k = 0; k <= 100; k++) {
            pd_wilson(k, 100, z, &lo, &hi);
            if (lo <= ps[t] && ps[t] <= hi)
                cov += pk;
            pk *= (double)(100 - k) / (double)(k + 1) * ps[t] / (1 - ps[t]);
        }
        CHECK(cov > 0.92 && cov < 0.98);
        if (t == 0)
            CHECK_NEAR(cov, 0.968772490568642, 1e-12, "exact binomial sum, computed independently in Python");
    }
}
