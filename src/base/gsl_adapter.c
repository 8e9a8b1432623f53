/* gsl_adapter.c: GSL behind posedrop's status codes (see gsl_adapter.h). */
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_multifit.h>
#include <gsl/gsl_multimin.h>
#include <gsl/gsl_odeiv2.h>
#include <gsl/gsl_poly.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_elljac.h>
#include <gsl/gsl_sf_gamma.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/gsl_adapter.h"

/* Subintervals QAGS may create. The band integrands are smooth apart from at
 * most one endpoint, where 64 bisections already reach round-off. */
enum { QUAD_INTERVALS = 64 };

typedef struct {
    pd_quad_fn fn;
    void *user;
} quad_call;

static double quad_trampoline(double x, void *p)
{
    const quad_call *c = p;
    return c->fn(x, c->user);
}

pd_status pd_quad_integrate(pd_quad_fn fn, void *user, double a, double b, double relerr,
                            double *result)
{
    gsl_set_error_handler_off();
    gsl_integration_workspace *w = gsl_integration_workspace_alloc(QUAD_INTERVALS);
    if (!w)
        return PD_ERR_NOMEM;
    quad_call call = {fn, user};
    gsl_function F = {quad_trampoline, &call};
    double value, abserr;
    int rc = gsl_integration_qags(&F, a, b, 0.0, relerr, QUAD_INTERVALS, w, &value, &abserr);
    gsl_integration_workspace_free(w);
    /* GSL_EROUND means round-off stopped further refinement, i.e. the result
     * is as good as double precision allows: accept it. */
    if (rc != GSL_SUCCESS && rc != GSL_EROUND)
        return PD_ERR_NO_CONVERGENCE;
    *result = value;
    return PD_OK;
}

/* --- distributions ---------------------------------------------------------- */

double pd_gsl_chisq_q(double x, double dof) { return gsl_cdf_chisq_Q(x, dof); }

double pd_gsl_lnpoch(double a, double x)
{
    gsl_sf_result r;
    gsl_set_error_handler_off();
    return gsl_sf_lnpoch_e(a, x, &r) == GSL_SUCCESS ? r.val : lgamma(a + x) - lgamma(a);
}

double pd_gsl_normal_quantile(double p) { return gsl_cdf_ugaussian_Pinv(p); }

double pd_gsl_beta_p(double x, double a, double b) { return gsl_cdf_beta_P(x, a, b); }

/* --- minimisation ------------------------------------------------------------ */

typedef struct {
    pd_min_fn fn;
    void *user;
    int evals, stop;
} min_call;

static double min_trampoline(const gsl_vector *v, void *p)
{
    min_call *c = p;
    c->evals++;
    /* gsl_vector's data is contiguous for a vector GSL allocated itself. */
    double f = c->fn(v->data, c->user);
    if (!isfinite(f)) {
        c->stop = 1;
        return GSL_POSINF;
    }
    return f;
}

pd_status pd_gsl_least_squares(int n, int p, const double *X, const double *y, double *c,
                               double *rss)
{
    gsl_set_error_handler_off();
    gsl_matrix *A = gsl_matrix_alloc((size_t)n, (size_t)p);
    gsl_matrix *cov = gsl_matrix_alloc((size_t)p, (size_t)p);
    gsl_vector *b = gsl_vector_alloc((size_t)n), *x = gsl_vector_alloc((size_t)p);
    gsl_multifit_linear_workspace *w = gsl_multifit_linear_alloc((size_t)n, (size_t)p);
    pd_status st = A && cov && b && x && w ? PD_OK : PD_ERR_NOMEM;
    if (st == PD_OK) {
        for (int i = 0; i < n; i++) {
            gsl_vector_set(b, (size_t)i, y[i]);
            for (int j = 0; j < p; j++)
                gsl_matrix_set(A, (size_t)i, (size_t)j, X[(size_t)i * (size_t)p + (size_t)j]);
        }
        if (gsl_multifit_linear(A, b, x, cov, rss, w) != GSL_SUCCESS)
            st = PD_ERR_NO_CONVERGENCE;
        for (int j = 0; st == PD_OK && j < p; j++)
            c[j] = gsl_vector_get(x, (size_t)j);
    }
    if (w)
        gsl_multifit_linear_free(w);
    if (x)
        gsl_vector_free(x);
    if (b)
        gsl_vector_free(b);
    if (cov)
        gsl_matrix_free(cov);
    if (A)
        gsl_matrix_free(A);
    return st;
}

pd_status pd_gsl_nelder_mead(pd_min_fn fn, void *user, int n, double *x, const double *step,
                             double size_tol, int max_evals, int *evals, double *fmin)
{
    gsl_set_error_handler_off();
    gsl_multimin_fminimizer *s = gsl_multimin_fminimizer_alloc(gsl_multimin_fminimizer_nmsimplex2,
                                                               (size_t)n);
    gsl_vector *x0 = gsl_vector_alloc((size_t)n), *dx = gsl_vector_alloc((size_t)n);
    pd_status st = PD_OK;
    min_call call = {fn, user, 0, 0};
    if (!s || !x0 || !dx)
        st = PD_ERR_NOMEM;
    if (st == PD_OK) {
        for (int i = 0; i < n; i++) {
            gsl_vector_set(x0, (size_t)i, x[i]);
            gsl_vector_set(dx, (size_t)i, step[i]);
        }
        gsl_multimin_function F = {min_trampoline, (size_t)n, &call};
        if (gsl_multimin_fminimizer_set(s, &F, x0, dx) != GSL_SUCCESS)
            st = call.stop ? PD_ERR_INTERNAL : PD_ERR_NO_CONVERGENCE;
        while (st == PD_OK && !call.stop && call.evals < max_evals) {
            int rc = gsl_multimin_fminimizer_iterate(s);
            if (call.stop)
                break;
            /* GSL_ENOPROG: the simplex cannot shrink further, a minimum
             * as good as the function's resolution allows. */
            if (rc != GSL_SUCCESS)
                break;
            if (gsl_multimin_test_size(gsl_multimin_fminimizer_size(s), size_tol) == GSL_SUCCESS)
                break;
        }
        if (st == PD_OK && call.stop)
            st = PD_ERR_INTERNAL;
        if (st == PD_OK) {
            for (int i = 0; i < n; i++)
                x[i] = gsl_vector_get(s->x, (size_t)i);
            *fmin = s->fval;
        }
    }
    *evals = call.evals;
    if (s)
        gsl_multimin_fminimizer_free(s);
    if (x0)
        gsl_vector_free(x0);
    if (dx)
        gsl_vector_free(dx);
    return st;
}

int pd_gsl_cubic_roots(double a, double b, double c, double x[3])
{
    return gsl_poly_solve_cubic(a, b, c, &x[0], &x[1], &x[2]);
}

/* GSL's samplers draw through a gsl_rng; this type makes one of posedrop's
 * streams that gsl_rng, so no GSL generator (and no GSL seeding convention)
 * enters the results. get gives the top 32 bits, get_double the same 53-bit
 * uniform as pd_rng_uniform. set is never called: the state is the caller's. */
static void stream_set(void *state, unsigned long seed)
{
    (void)state;
    (void)seed;
}

static unsigned long stream_get(void *state) { return (unsigned long)(pd_rng_u64(state) >> 32); }

static double stream_get_double(void *state) { return pd_rng_uniform(state); }

static const gsl_rng_type stream_type = {"posedrop-stream", 0xffffffffUL, 0, sizeof(pd_rng),
                                         stream_set, stream_get, stream_get_double};

void pd_gsl_multinomial(pd_rng *rng, int k, unsigned total, const double *w, unsigned *out)
{
    gsl_rng r = {&stream_type, rng};
    gsl_ran_multinomial(&r, (size_t)k, total, w, out);
}

/* ==== Elliptic functions (flight: torque-free rotation) ===============
 * See gsl_adapter.h. GSL_PREC_DOUBLE: the flight promises conservation and
 * phase to ~1e-12 relative, so the full double accuracy is needed. */

pd_status pd_elljac(double u, double m, double *sn, double *cn, double *dn)
{
    gsl_set_error_handler_off();
    return gsl_sf_elljac_e(u, m, sn, cn, dn) == GSL_SUCCESS ? PD_OK : PD_ERR_NONFINITE;
}

/* A special function's GSL status and result as a pd_status and a value.
 * Callers switch the error handler off before the call. */
static pd_status sf_value(int rc, const gsl_sf_result *r, double *result)
{
    if (rc != GSL_SUCCESS)
        return PD_ERR_NONFINITE;
    *result = r->val;
    return PD_OK;
}

pd_status pd_ellint_F(double phi, double k, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    return sf_value(gsl_sf_ellint_F_e(phi, k, GSL_PREC_DOUBLE, &r), &r, result);
}

pd_status pd_ellint_P(double phi, double k, double n, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    return sf_value(gsl_sf_ellint_P_e(phi, k, n, GSL_PREC_DOUBLE, &r), &r, result);
}

pd_status pd_ellint_Kcomp(double k, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    return sf_value(gsl_sf_ellint_Kcomp_e(k, GSL_PREC_DOUBLE, &r), &r, result);
}

pd_status pd_ellint_Pcomp(double k, double n, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    return sf_value(gsl_sf_ellint_Pcomp_e(k, n, GSL_PREC_DOUBLE, &r), &r, result);
}
pd_status pd_ellint_RF(double x, double y, double z, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    return sf_value(gsl_sf_ellint_RF_e(x, y, z, GSL_PREC_DOUBLE, &r), &r, result);
}
/* ==== end of elliptic functions ============================================= */
/* --- ODE integration (see gsl_adapter.h) ------------------------------------ */

struct pd_ode {
    int dim;
    gsl_odeiv2_step *step;
    gsl_odeiv2_control *control;
    double *y0, *yerr; /* pd_ode_step_from's: the step's start, its error estimate */
};

pd_ode *pd_ode_alloc(int dim, double eps_abs, double eps_rel)
{
    /* rk8pd: the collision ODE is smooth between events and asked for ~1e-9,
     * where an 8th-order pair takes far fewer right-hand-side evaluations
     * than a 4th/5th-order pair (cost ~ tol^(-1/8) vs tol^(-1/5)). */
    return pd_ode_alloc_method(PD_ODE_RK8PD, dim, eps_abs, eps_rel);
}

pd_ode *pd_ode_alloc_method(pd_ode_method method, int dim, double eps_abs, double eps_rel)
{
    gsl_set_error_handler_off();
    pd_ode *ode = calloc(1, sizeof *ode);
    if (!ode)
        return NULL;
    ode->dim = dim;
    const gsl_odeiv2_step_type *type =
        method == PD_ODE_RKCK ? gsl_odeiv2_step_rkck : gsl_odeiv2_step_rk8pd;
    ode->step = gsl_odeiv2_step_alloc(type, (size_t)dim);
    ode->control = gsl_odeiv2_control_y_new(eps_abs, eps_rel);
    ode->y0 = malloc((size_t)dim * sizeof *ode->y0);
    ode->yerr = malloc((size_t)dim * sizeof *ode->yerr);
    if (!ode->step || !ode->control || !ode->y0 || !ode->yerr) {
        pd_ode_free(ode);
        return NULL;
    }
    return ode;
}

void pd_ode_free(pd_ode *ode)
{
    if (!ode)
        return;
    if (ode->control)
        gsl_odeiv2_control_free(ode->control);
    if (ode->step)
        gsl_odeiv2_step_free(ode->step);
    free(ode->y0);
    free(ode->yerr);
    free(ode);
}

/* GSL's evolve_apply's adaptive step (the same stages, control, and retries
 * of a step the control rejects), but with the derivative at the start from
 * the caller. evolve_apply takes it from the previous step's end, for which
 * the stepper evaluates fn once more in every attempt (rejected ones
 * included), or evaluates it itself after a reset; a control on y alone
 * never reads it. A failure of fn ends the step at once (evolve_apply would
 * halve it down to round-off): the caller knows better what to do. */
pd_status pd_ode_step_from(pd_ode *ode, pd_ode_fn fn, void *user, double *t, double t1, double *h,
                           double y[], const double dydt_in[])
{
    gsl_odeiv2_system sys = {fn, NULL, (size_t)ode->dim, user};
    size_t bytes = (size_t)ode->dim * sizeof *y;
    const double t0 = *t;
    double h0 = *h;
    memcpy(ode->y0, y, bytes);
    for (;;) {
        int final_step = h0 > t1 - t0;
        if (final_step)
            h0 = t1 - t0;
        if (gsl_odeiv2_step_apply(ode->step, t0, h0, y, ode->yerr, dydt_in, NULL, &sys) !=
            GSL_SUCCESS) {
            memcpy(y, ode->y0, bytes);
            return PD_ERR_INTERNAL;
        }
        /* The control weighs the derivative by zero (a control on y): the
         * start's stands in for the end's, which was not computed. */
        double taken = h0;
        if (gsl_odeiv2_control_hadjust(ode->control, ode->step, y, ode->yerr, dydt_in, &h0) ==
            GSL_ODEIV_HADJ_DEC) {
            memcpy(y, ode->y0, bytes);
            if (h0 < taken && t0 + h0 != t0)
                continue;
            return PD_ERR_NO_CONVERGENCE;
        }
        *t = final_step ? t1 : t0 + taken;
        if (!final_step)
            *h = h0;
        return PD_OK;
    }
}

/* --- end of ODE integration ---------------------------------------------------- */
