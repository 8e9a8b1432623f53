/* flight_theta.c: Jacobi's elliptic functions and Legendre's third-kind
 * integral along a polhode by theta series (see flight_theta.h).
 *
 * With K, K' the complete integrals of parameters m and 1 - m, the nome
 * q = exp(-pi K'/K) and v = pi tau / (2K) (Whittaker & Watson, ch. 21-22):
 *   sn = (th3/th2) th1(v)/th4(v), cn = (th4/th2) th2(v)/th4(v),
 *   dn = (th4/th3) th3(v)/th4(v),   th_j = th_j(0),
 *   th1(v) ~ sum (-1)^k q^(k(k+1)) sin((2k+1)v), th2(v) ~ sum q^(k(k+1)) cos((2k+1)v)
 *   (a common factor 2 q^(1/4) dropped), th3, th4 = 1 + 2 sum (+-1)^k q^(k^2) cos(2kv).
 *
 * Third kind (our derivation). For n > 0 the integrand 1/(1 + n sn^2) is
 * 1/(1 - m sn^2(a) sn^2) at a = i beta, sc(beta, k')^2 = n/m, and Jacobi's
 * Pi(u, a) = u Z(a) + ln(Theta(u - a)/Theta(u + a)) / 2 turns into
 *   P(tau) = mu tau + sigma arg X(v),   X(v) = th4(v + i pi beta/(2K)),
 *   sigma = sn cn / dn (beta, k') = sqrt(n / ((m + n)(1 + n))),
 * mu the mean slope (mu = Pi(k, n)/K), fixed here by P'(0) = 1 from the
 * series itself. Beta can lie anywhere in (0, K'); near K' (a polhode
 * circling an axis of a nearly symmetric body, n large) X passes close to a
 * zero of th4, and the terms of th4's series cancel. So X is taken from the
 * other side of the period: gamma = K' - beta = F(atan(1/sqrt n), k') (the
 * addition theorem: F(a) + F(b) = K' when tan a tan b = 1/k), and th4(z +
 * i pi K'/(2K)) = i q^(-1/4) e^(-iz) th1(z) give, up to a positive factor,
 *   X(v) ~ e^(-iv) Y(v),   Y(v) = sum (-1)^k q^(k(k+1)) sinh((2k+1)(w + i v)),
 *   w = pi gamma / (2K),
 * where sinh(w + iv) = sinh w cos v + i cosh w sin v keeps its relative
 * accuracy however small w and v are. (Checked while deriving against
 * 30-digit quadrature of P, to 1e-30, at (m, n) = (0.3, 2), (1e-4, 4.3),
 * (0.9, 0.23); tests/unit/test_flight.c checks the flight against an ODE.)
 *
 * Truncation: relative to the leading term, term k of every series is at
 * most q^(k^2) (e^(2w) <= e^(pi K'/K) = 1/q since gamma <= K'), so the
 * series stop at the first k with q^(k^2) <= PD_TOL_FLIGHT_SERIES.
 *
 * The plan takes K and K' from Gauss's mean (agm), the incomplete
 * integrals tau0 and gamma from Carlson's RF by duplication (carlson_rf,
 * half the instructions of GSL's and no less accurate: against a long
 * double reference over the plan's arguments, worst 5.9e-16 relative, GSL
 * 6.8e-16), and the coefficients by recurrence; the flight (flight.c)
 * folds arg Y(v0) into its constant rotation, so evaluation needs Y(v)
 * alone, unnormalised. */
#include <math.h>
#include "dynamics/flight_theta.h"
#include "base/sincos.h"
#include "dynamics/dynamics_tol.h"

static const double PI = 3.14159265358979323846;

/* th1..th4 at v (th1, th2 without their factor 2 q^(1/4)) into f, and Y(v)
 * into Y: one sincos, the odd multiples by complex rotation and each even
 * one, whose cosine alone is used, as the real part of the odd one below
 * it times e^(iv). */
static void series(const pd_theta *th, double v, double f[4], double Y[2])
{
    double s, c;
    pd_sincos(v, &s, &c);
    double e2r = c * c - s * s, e2i = 2.0 * s * c;
    double odr = c, odi = s; /* e^(i (2k+1) v) */
    double t1 = odi, t2 = odr, t3 = 0.0, t4 = 0.0;
    double yr = th->S[0] * odr, yi = th->C[0] * odi;
    for (int k = 1; k < th->nterms; k++) {
        double ev = odr * c - odi * s; /* cos 2kv */
        double r = odr * e2r - odi * e2i;
        odi = odr * e2i + odi * e2r;
        odr = r;
        t1 += th->qos[k] * odi;
        t2 += th->qo[k] * odr;
        yr += th->S[k] * odr;
        yi += th->C[k] * odi;
        t3 += th->qe[k] * ev;
        t4 += th->qes[k] * ev;
    }
    f[0] = t1;
    f[1] = t2;
    f[2] = 1.0 + 2.0 * t3;
    f[3] = 1.0 + 2.0 * t4;
    Y[0] = yr;
    Y[1] = yi;
}

/* Gauss's arithmetic-geometric mean of a >= b > 0, so that K(k) = pi / (2
 * AGM(1, k')): quadratic convergence, so once a and b agree to 2^-27 one
 * more step leaves an error of (2^-27)^2 / 16, below round-off; each step
 * is exact to an ulp and the mean does not amplify errors. b = 1e-3 takes
 * 6 steps, b = 1e-300 12; the bound only stops a NaN. */
static double agm(double a, double b)
{
    for (int i = 0; i < 64 && a - b > 0x1p-27 * a; i++) {
        double g = sqrt(a * b);
        a = 0.5 * (a + b);
        b = g;
    }
    return 0.5 * (a + b);
}

/* Carlson's symmetric integral RF(x, y, z), x, y, z >= 0, at most one zero,
 * by the duplication theorem (DLMF 19.26.18): with l = sqrt(x y) + sqrt(y z)
 * + sqrt(z x), RF(x, y, z) = RF((x + l)/4, (y + l)/4, (z + l)/4), which
 * draws the arguments together by a factor 4 a step while their mean A
 * shrinks by at most 4, then the Taylor series about the mean through
 * degree 7 (DLMF 19.36.1) in X = (A0 - x0) / (4^j A), Y likewise, Z = -X -
 * Y (Carlson's form: the deviations without cancellation). Its terms of
 * degree d are at most e^d, e = max(|X|, |Y|, |Z|) (the coefficients of
 * R_-1/2 are below 1), so stopping at e <= 2^-7 leaves e^8 / (1 - e) <
 * 1.5e-17 relative, below round-off. Arguments a factor 10 apart take 4
 * steps. The bound only stops a NaN. */
static double carlson_rf(double x, double y, double z)
{
    double A0 = (x + y + z) / 3.0, A = A0;
    double dx = A0 - x, dy = A0 - y;
    double span = 128.0 * fmax(fabs(dx), fmax(fabs(dy), fabs(A0 - z))), f = 1.0;
    for (int i = 0; i < 64 && span * f > A; i++) {
        double sx = sqrt(x), sy = sqrt(y), sz = sqrt(z);
        double l = sx * (sy + sz) + sy * sz;
        x = 0.25 * (x + l);
        y = 0.25 * (y + l);
        z = 0.25 * (z + l);
        A = 0.25 * (A + l);
        f *= 0.25;
    }
    double X = dx * f / A, Y = dy * f / A, Z = -(X + Y);
    double E2 = X * Y - Z * Z, E3 = X * Y * Z;
    double small = E2 * (-1.0 / 10.0 + E2 * (1.0 / 24.0 - E2 * (5.0 / 208.0))) +
                   E3 * (1.0 / 14.0 + E3 * (3.0 / 104.0) + E2 * (-3.0 / 44.0 + E2 / 16.0));
    return (1.0 + small) / sqrt(A);
}

pd_status pd_theta_plan(pd_theta *th, double m, double mc, double n, double sn0, double cn0,
                        double omega)
{
    if (!(m > 0.0 && mc > 0.0 && n > 0.0 && m <= 1.0 && mc <= 1.0))
        return PD_ERR_RANGE;
    /* K = pi / (2 AGM(1, k')), K' = pi / (2 AGM(1, k)); F(phi, k) = sin phi
     * RF(cos^2 phi, 1 - m sin^2 phi, 1), here in RF's homogeneous form
     * (RF(l x, l y, l z) = RF(x, y, z) / sqrt l): no normalisation needed. */
    double Ka = agm(1.0, sqrt(mc)), Kpa = agm(1.0, sqrt(m));
    double K = 0.5 * PI / Ka;
    double s2 = sn0 * sn0, c2 = cn0 * cn0;
    double q = exp(-PI * Ka / Kpa);
    if (!(q <= PD_FLIGHT_NOME_MAX))
        return PD_ERR_RANGE;
    double R = carlson_rf(c2, c2 + mc * s2, c2 + s2), gamma = carlson_rf(n, n + m, 1.0 + n);
    /* tau0 = F(am0) with am0 in (-pi, pi]: past a quarter period (cn0 < 0)
     * by the reflection F(pi - am) = 2K - F(am). */
    double tau0 = cn0 >= 0.0 ? sn0 * R : copysign(2.0 * K, sn0) - sn0 * R;
    double scale = PI / (2.0 * K);
    th->v0 = scale * tau0;
    th->nu = scale * omega;
    double w = scale * gamma;
    /* sinh((2k+1) w), cosh((2k+1) w) by the recurrence
     * f_(k+1) = 2 cosh(2w) f_k - f_(k-1) from sinh w (via expm1: exact for
     * small w) and cosh w; every term grows, so none cancels. */
    double em = expm1(w), E = 1.0 + em;
    double sh = em * (em + 2.0) / (2.0 * E), ch = 0.5 * (E + 1.0 / E);
    double c2w = 1.0 + 2.0 * sh * sh;
    double sp = -sh, cp = ch, sk = sh, ck = ch;
    double qk2 = 1.0, qkk = 1.0, q2k1 = q, sign = 1.0;
    double t2 = 0.0, t3 = 0.0, t4 = 0.0, sumS = 0.0, sumC = 0.0;
    int k = 0;
    for (; k < PD_THETA_TERMS && (k == 0 || qk2 > PD_TOL_FLIGHT_SERIES); k++) {
        th->qo[k] = qkk;
        th->qos[k] = sign * qkk;
        th->qe[k] = qk2;
        th->qes[k] = sign * qk2;
        th->S[k] = sign * qkk * sk;
        th->C[k] = sign * qkk * ck;
        t2 += qkk;
        if (k > 0) {
            t3 += qk2;
            t4 += sign * qk2;
        }
        sumS += th->S[k];
        sumC += (2 * k + 1) * th->C[k];
        /* q^((k+1)^2) = q^(k^2) q^(2k+1), q^((k+1)(k+2)) = q^(k(k+1)) q^(2k+2) */
        qk2 *= q2k1;
        qkk *= q2k1 * q;
        q2k1 *= q * q;
        double s = 2.0 * c2w * sk - sp, c = 2.0 * c2w * ck - cp;
        sp = sk, cp = ck, sk = s, ck = c;
        sign = -sign;
    }
    if (qk2 > PD_TOL_FLIGHT_SERIES)
        return PD_ERR_RANGE; /* more terms needed than kept */
    th->nterms = k;
    double th3 = 1.0 + 2.0 * t3, th4 = 1.0 + 2.0 * t4;
    th->csn = th3 / t2;
    th->ccn = th4 / t2;
    th->cdn = th4 / th3;
    /* P'(0) = 1 = mu + sigma (pi/2K) d arg X/dv (0), d arg X/dv (0) =
     * -1 + Y'(0)/(i Y(0)) = -1 + sum (2k+1) C_k / sum S_k. */
    double sigma = sqrt(n / ((m + n) * (1.0 + n)));
    th->mu = 1.0 - sigma * scale * (sumC / sumS - 1.0);
    if (!isfinite(th->mu + th->v0 + th->nu + th->csn + th->ccn + th->cdn + sumS + sumC))
        return PD_ERR_NONFINITE;
    return PD_OK;
}

void pd_theta_eval(const pd_theta *th, double t, double *sn, double *cn, double *dn, double y[2])
{
    double f[4];
    series(th, th->v0 + th->nu * t, f, y);
    double r = 1.0 / f[3];
    *sn = th->csn * f[0] * r;
    *cn = th->ccn * f[1] * r;
    *dn = th->cdn * f[2] * r;
}
