/* stats.c: Wilson intervals and sample sizes (see stats.h). */
#include <limits.h>
#include <math.h>
#include "base/gsl_adapter.h"
#include "base/stats.h"

void pd_wilson(long k, long n, double z, double *lo, double *hi)
{
    if (n <= 0) {
        *lo = 0.0;
        *hi = 1.0;
        return;
    }
    double p = (double)k / (double)n, z2n = z * z / (double)n;
    double centre = (p + 0.5 * z2n) / (1.0 + z2n);
    double half = z * sqrt(p * (1.0 - p) / (double)n + 0.25 * z2n / (double)n) / (1.0 + z2n);
    /* At k = 0 (k = n) the lower (upper) end is 0 (1) exactly, the root of
     * the interval's quadratic at p = 0; centre - half would leave round-off
     * like 5.55e-17 there, outside which p = 0 would lie. */
    *lo = k <= 0 ? 0.0 : fmax(0.0, centre - half);
    *hi = k >= n ? 1.0 : fmin(1.0, centre + half);
}

long pd_sample_size(double delta, double alpha, int k)
{
    double z = pd_gsl_normal_quantile(1.0 - alpha / (2.0 * (k > 0 ? k : 1)));
    /* A half-width of 1e-20 asks for more drops than a long counts:
     * converting that double would be undefined. */
    double n = ceil(z * z / (4.0 * delta * delta));
    return n < (double)LONG_MAX ? (long)n : LONG_MAX;
}
