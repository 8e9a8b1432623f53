/* gsl_adapter.c: GSL behind posedrop's status codes (see gsl_adapter.h). */
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include "gsl_adapter.h"

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

double pd_gsl_normal_quantile(double p) { return gsl_cdf_ugaussian_Pinv(p); }

/* ==== Elliptic functions (flight: torque-free rotation) ======================
 * See gsl_adapter.h. GSL_PREC_DOUBLE: the flight promises conservation and
 * phase to ~1e-12 relative, so the full double accuracy is needed. */
#include <gsl/gsl_sf_ellint.h>
#include <gsl/gsl_sf_elljac.h>

pd_status pd_elljac(double u, double m, double *sn, double *cn, double *dn)
{
    gsl_set_error_handler_off();
    return gsl_sf_elljac_e(u, m, sn, cn, dn) == GSL_SUCCESS ? PD_OK : PD_ERR_NONFINITE;
}

pd_status pd_ellint_F(double phi, double k, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    if (gsl_sf_ellint_F_e(phi, k, GSL_PREC_DOUBLE, &r) != GSL_SUCCESS)
        return PD_ERR_NONFINITE;
    *result = r.val;
    return PD_OK;
}

pd_status pd_ellint_P(double phi, double k, double n, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    if (gsl_sf_ellint_P_e(phi, k, n, GSL_PREC_DOUBLE, &r) != GSL_SUCCESS)
        return PD_ERR_NONFINITE;
    *result = r.val;
    return PD_OK;
}

pd_status pd_ellint_Kcomp(double k, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    if (gsl_sf_ellint_Kcomp_e(k, GSL_PREC_DOUBLE, &r) != GSL_SUCCESS)
        return PD_ERR_NONFINITE;
    *result = r.val;
    return PD_OK;
}

pd_status pd_ellint_Pcomp(double k, double n, double *result)
{
    gsl_set_error_handler_off();
    gsl_sf_result r;
    if (gsl_sf_ellint_Pcomp_e(k, n, GSL_PREC_DOUBLE, &r) != GSL_SUCCESS)
        return PD_ERR_NONFINITE;
    *result = r.val;
    return PD_OK;
}
/* ==== end of elliptic functions ============================================= */
