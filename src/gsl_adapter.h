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

/* ==== Elliptic functions (flight: torque-free rotation) ======================
 * Thin wrappers on GSL's special functions, error handler off, GSL status
 * turned into PD_ERR_NONFINITE (a domain error can only come from a bad
 * argument). k is the modulus, m = k^2 the parameter, as in GSL. */

/* Jacobi elliptic functions sn, cn, dn of u with parameter m in [0, 1]. */
pd_status pd_elljac(double u, double m, double *sn, double *cn, double *dn);

/* Legendre incomplete integrals: F(phi, k) and
 * P(phi, k, n) = integral_0^phi dt / ((1 + n sin^2 t) sqrt(1 - k^2 sin^2 t)),
 * note the + n (GSL's convention, not Abramowitz & Stegun's). */
pd_status pd_ellint_F(double phi, double k, double *result);
pd_status pd_ellint_P(double phi, double k, double n, double *result);

/* Complete integrals K(k) = F(pi/2, k) and Pi(k, n) = P(pi/2, k, n); k < 1. */
pd_status pd_ellint_Kcomp(double k, double *result);
pd_status pd_ellint_Pcomp(double k, double n, double *result);
/* ==== end of elliptic functions ============================================= */

#endif
