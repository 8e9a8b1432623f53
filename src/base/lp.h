/* lp.h (private): a small linear program in up to PD_LP_MAXDIM variables,
 * by Seidel's randomized incremental algorithm (expected time linear in the
 * number of constraints for a fixed dimension).
 *
 * Floating point, with no guarantee beyond its round-off: callers use the
 * answer as a candidate that they verify exactly, never as a decision. */
#ifndef PD_LP_H
#define PD_LP_H

#define PD_LP_MAXDIM 4

/* One constraint: a . y <= b. */
typedef struct pd_lp_halfspace {
    double a[PD_LP_MAXDIM], b;
} pd_lp_halfspace;

/* Maximizes c . y over the d variables y (1 <= d <= PD_LP_MAXDIM) subject to
 * the k constraints h (taken in the given order: the caller shuffles them
 * for the expected time) and lo[j] <= y[j] <= hi[j]. 1 with the optimum in
 * y, 0 when infeasible (to the round-off tolerance tol, in the units of b),
 * -1 when out of memory. */
int pd_lp_solve(int d, const pd_lp_halfspace *h, int k, const double *c, const double *lo,
                const double *hi, double tol, double *y);

#endif
