/* stats.h (private): the statistics of Monte Carlo pose counts. */
#ifndef PD_STATS_H
#define PD_STATS_H

/* The two-sided normal quantile of 95% confidence, Phi^-1(0.975): every
 * interval the library reports uses it. */
#define PD_Z95 1.959963984540054

/* Wilson score interval for k successes in n trials at the confidence whose
 * two-sided normal quantile is z (1.96 for 95%): better than the normal
 * interval near 0 and 1, where most pose probabilities of real parts live,
 * and never outside [0, 1]. n = 0 gives [0, 1]. */
void pd_wilson(long k, long n, double z, double *lo, double *hi);

/* Drops needed so that every one of k pose probabilities is within delta at
 * confidence 1 - alpha at once, in the worst case p = 1/2: the paper's eq.
 * (17) with its missing square restored, (z / (2 delta))^2, and z the
 * Bonferroni quantile Phi^-1(1 - alpha / (2k)) (docs/readings.md, "Sample
 * size, eq. 17"). */
long pd_sample_size(double delta, double alpha, int k);

#endif
