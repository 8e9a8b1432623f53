/* gsl_adapter.h (private): the only door to GSL.
 *
 * GSL's default error handler aborts the process; a library must not, so the
 * adapter switches it off and turns GSL's return codes into pd_status. No
 * other file includes a GSL header. */
#ifndef PD_GSL_ADAPTER_H
#define PD_GSL_ADAPTER_H

#include "posedrop/status.h"

typedef double (*pd_quad_fn)(double x, void *user);

/* Integral of fn over [a, b] to relative accuracy relerr, by GSL's adaptive
 * Gauss-Kronrod quadrature with extrapolation (QAGS), which copes with the
 * integrable endpoint singularities a spherical band integrand can have.
 * PD_ERR_NO_CONVERGENCE if the accuracy is not reached, PD_ERR_NOMEM. */
pd_status pd_quad_integrate(pd_quad_fn fn, void *user, double a, double b, double relerr,
                            double *result);

/* Distribution functions (GSL's cdf module). */
double pd_gsl_chisq_q(double x, double dof);        /* P(chi2_dof > x) */
double pd_gsl_normal_quantile(double p);            /* Phi^-1(p), p in (0, 1) */

#endif
