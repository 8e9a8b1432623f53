/* flight_theta.h (private): the asymmetric top's elliptic functions by
 * Jacobi's theta series (flight.c's fast path).
 *
 * Along a polhode the flight needs sn, cn, dn of tau = tau0 + Omega t and
 * Legendre's third-kind integral P(tau) = integral_0^tau dx / (1 + n sn^2 x)
 * (GSL's sign of n). Both are set up here once per flight so that each
 * evaluation costs one sincos and a few terms of rapidly converging series:
 * no incomplete integral, no arc tangent. flight_theta.c derives the forms. */
#ifndef PD_FLIGHT_THETA_H
#define PD_FLIGHT_THETA_H

#include "posedrop/status.h"

/* Series terms kept at most: enough for nomes up to PD_FLIGHT_NOME_MAX at the
 * truncation PD_TOL_FLIGHT_SERIES (flight_theta.c). */
enum { PD_THETA_TERMS = 14 };

typedef struct pd_theta {
    int nterms;
    double v0, nu;                 /* v = pi tau / (2K) = v0 + nu t */
    double mu;                     /* P(tau) = mu tau + sigma arg X(v): mean slope */
    double qo[PD_THETA_TERMS];     /* q^(k(k+1)): theta2 */
    double qos[PD_THETA_TERMS];    /* (-1)^k q^(k(k+1)): theta1 */
    double qe[PD_THETA_TERMS];     /* q^(k^2): theta3 */
    double qes[PD_THETA_TERMS];    /* (-1)^k q^(k^2): theta4 */
    double S[PD_THETA_TERMS];      /* (-1)^k q^(k(k+1)) sinh((2k+1) w) */
    double C[PD_THETA_TERMS];      /* (-1)^k q^(k(k+1)) cosh((2k+1) w) */
    double csn, ccn, cdn;          /* theta-constant ratios of sn, cn, dn */
} pd_theta;

/* Plans the functions of parameter m (0 < m < 1; mc = 1 - m, passed separately
 * so that it keeps its accuracy near m = 1), characteristic n > 0, starting
 * at the point sn = sn0, cn = cn0 of the period (any scale: only their ratio
 * is used) and moving at d tau / dt = omega. PD_ERR_RANGE when the nome
 * exceeds PD_FLIGHT_NOME_MAX (near the separatrix), where the caller uses
 * Legendre's integrals instead; PD_ERR_NONFINITE if a planned value is not
 * finite. */
pd_status pd_theta_plan(pd_theta *th, double m, double mc, double n, double sn0, double cn0,
                        double omega);

/* sn, cn, dn at time t, and Y(v), e^(iv) X(v) up to a positive factor, in
 * y[0] + i y[1] (only its argument is meant), so that arg Y(v) - arg Y(v0) -
 * (v - v0) is P(tau) - P(tau0) - mu (tau - tau0) over sigma = sqrt(n / ((m
 * + n)(1 + n))). */
void pd_theta_eval(const pd_theta *th, double t, double *sn, double *cn, double *dn, double y[2]);

#endif
