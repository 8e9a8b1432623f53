/* gsl_adapter.h (private): the only door to GSL.
 *
 * GSL's default error handler aborts the process; a library must not, so the
 * adapter switches it off and turns GSL's return codes into pd_status. No
 * other file includes a GSL header. */
#ifndef PD_GSL_ADAPTER_H
#define PD_GSL_ADAPTER_H

#include "posedrop/status.h"
#include "base/rng.h"

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
double pd_gsl_beta_p(double x, double a, double b); /* P(X <= x), X ~ Beta(a, b) */
/* log Gamma(a + x) - log Gamma(a) for a > 0, x >= 0, without the cancellation
 * of the difference of two large lgamma values (GSL's lnpoch). */
double pd_gsl_lnpoch(double a, double x);

/* The real roots of x^3 + a x^2 + b x + c, ascending, into x[0..n); returns n
 * (1 or 3; a double root is reported twice). GSL's closed form, no iteration. */
int pd_gsl_cubic_roots(double a, double b, double c, double x[3]);

/* One multinomial draw: out[0..k) counts of `total` trials over k categories
 * of weights w[0..k) (non-negative, not all zero, normalised by GSL), drawn
 * from rng, one of posedrop's own streams, so the draw is as reproducible as
 * a drop. GSL's conditional binomials: O(k) whatever total is. */
void pd_gsl_multinomial(pd_rng *rng, int k, unsigned total, const double *w, unsigned *out);

/* Minimises fn over R^n by GSL's Nelder-Mead simplex (nmsimplex2), from x
 * (n values, overwritten by the best point found) with initial steps step
 * (n values), until the simplex's characteristic size is below size_tol or
 * max_evals evaluations were spent (*evals receives the count; a step
 * may overrun max_evals by the n + 1 evaluations of a shrink). *fmin is the
 * value at x. fn returns a finite value, or a non-finite one to stop the
 * search: then PD_ERR_INTERNAL, the callee keeping its own reason.
 * PD_ERR_NO_CONVERGENCE if the first simplex cannot be set, PD_ERR_NOMEM. */
typedef double (*pd_min_fn)(const double *x, void *user);
pd_status pd_gsl_nelder_mead(pd_min_fn fn, void *user, int n, double *x, const double *step,
                             double size_tol, int max_evals, int *evals, double *fmin);

/* Ordinary least squares: the p coefficients c minimising |y - X c|^2 for
 * the n x p matrix X (row-major, n > p) and y (n values), by GSL's
 * multifit_linear (SVD, so a rank-deficient X gives the minimum-norm
 * solution rather than failing); *rss receives the residual sum of squares.
 * PD_ERR_NOMEM, or PD_ERR_NO_CONVERGENCE if GSL fails. */
pd_status pd_gsl_least_squares(int n, int p, const double *X, const double *y, double *c,
                               double *rss);

/* ==== Elliptic functions (flight: torque-free rotation) ===============
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

/* Carlson's symmetric integral R_F(x, y, z) = (1/2) integral_0^inf dt /
 * sqrt((t + x)(t + y)(t + z)), x, y, z >= 0, at most one of them 0. */
pd_status pd_ellint_RF(double x, double y, double z, double *result);
/* ==== end of elliptic functions ============================================= */
/* --- ODE integration (used by impact.c and contact_phase.c) -----------------
 * One adaptive embedded Runge-Kutta integrator (GSL's rk8pd, Prince-Dormand
 * 8(9), or rkck, Cash-Karp 4(5), with step control on |y|), allocated once
 * and reused: pd_ode_step_from allocates nothing, so a per-thread workspace can
 * serve every collision. */

typedef struct pd_ode pd_ode;

/* The embedded pair: rk8pd, 12 new right-hand sides a step given the
 * start's derivative, pays off at tight tolerances over long stretches;
 * rkck, 5 a step, at looser ones or where events cut the steps short. */
typedef enum { PD_ODE_RK8PD, PD_ODE_RKCK } pd_ode_method;

/* Right-hand side dy/dt = f(t, y); returns 0 (any other value aborts the
 * step and pd_ode_step_from reports PD_ERR_INTERNAL). Same shape as GSL's, so it
 * is handed to GSL without a trampoline. */
typedef int (*pd_ode_fn)(double t, const double y[], double dydt[], void *user);

/* An integrator for systems of dim unknowns, each step held to
 * eps_abs + eps_rel * |y_i| local error. NULL if allocation fails. */
pd_ode *pd_ode_alloc(int dim, double eps_abs, double eps_rel);
/* The same with the pair of the caller's choice (pd_ode_alloc: rk8pd). */
pd_ode *pd_ode_alloc_method(pd_ode_method method, int dim, double eps_abs, double eps_rel);
void pd_ode_free(pd_ode *ode);

/* One accepted adaptive step from (*t, y) towards t1 > *t, never past t1
 * (landing exactly on t1 when it reaches it), given dydt_in = fn(*t, y),
 * which the callers have anyway: no end derivative is evaluated and no
 * history kept, so a step may start from any state. *h is the step to try,
 * updated to the one suggested for the next step. PD_ERR_NO_CONVERGENCE
 * when the step size falls to round-off of t, PD_ERR_INTERNAL when fn
 * fails; on either, *t and y are the step's start. */
pd_status pd_ode_step_from(pd_ode *ode, pd_ode_fn fn, void *user, double *t, double t1, double *h,
                           double y[], const double dydt_in[]);

#endif
