/* impact_rays.c: the invariant rays of a collision's tangential flow (see
 * impact_rays.h). */
#include <float.h>
#include <math.h>
#include "base/gsl_adapter.h"
#include "impact/impact.h"
#include "impact/impact_rays.h"
#include "impact/impact_tol.h"
#include "base/vec3.h"

/* --- the diverging ray ------------------------------------------------------- *
 * Trajectories leave the origin along an invariant ray when lambda > 0. Then
 * (mu B + lambda I) t = a, so t = (mu B + lambda I)^-1 a with |t| = 1: lambda
 * solves phi(lambda) = |(mu B + lambda I)^-1 a|^2 = 1. For lambda >= 0, phi is
 * strictly decreasing (B is positive definite) from phi(0) = |B^-1 a|^2 / mu^2
 * to 0; so an outward ray exists, and is unique, exactly when
 * |B^-1 a| > mu, which is eq. 15's condition for unstable sticking. This is
 * the statement the paper makes without proof ("this ray always exists and is
 * unique"); Mirtich's thesis, which the paper follows, was corrected on
 * resumed sliding by R. Baber (2011), whose note we could not consult, so the
 * construction here is derived directly from eq. 14 rather than taken from it.
 * Newton's method on psi(lambda) = 1/sqrt(phi) - 1 finds it: 1/|t(lambda)|
 * is concave and increasing in lambda (the secular function of trust-region
 * methods; it is exactly linear when a is an eigenvector of B), so Newton
 * from lambda = 0, where psi < 0, climbs monotonically to the root without
 * overshoot and converges quadratically: 4-6 steps, no bracket to keep, no
 * trigonometry. (Bisection took ~50 steps, 10% of a whole drop.) */

enum { RAY_NEWTON = 100 };

/* t = M^-1 a, M = mu B + lam I, and t' M^-1 t (for the derivative). */
static double ray_phi(const double K[3][3], double mu, double lam, double *tx, double *ty,
                      double *tMt)
{
    double m00 = mu * K[0][0] + lam, m01 = mu * K[0][1], m11 = mu * K[1][1] + lam;
    double det = m00 * m11 - m01 * m01;
    *tx = (m11 * K[0][2] - m01 * K[1][2]) / det;
    *ty = (m00 * K[1][2] - m01 * K[0][2]) / det;
    double sx = (m11 * *tx - m01 * *ty) / det, sy = (m00 * *ty - m01 * *tx) / det;
    *tMt = *tx * sx + *ty * sy;
    return *tx * *tx + *ty * *ty;
}

int pd_ray_diverging(const double K[][3], double mu, double *rx, double *ry)
{
    double tx, ty, tMt, lam = 0.0;
    double phi = mu > 0.0 ? ray_phi(K, mu, 0.0, &tx, &ty, &tMt) : 0.0;
    if (!(phi > 1.0))
        return 0;
    for (int i = 0; i < RAY_NEWTON; i++) {
        double r = sqrt(phi);
        /* psi = 1/r - 1, psi' = tMt / r^3. */
        double step = (r - 1.0) * r * r / tMt;
        if (!(step > 4.0 * DBL_EPSILON * lam))
            break; /* at the root to round-off (r <= 1 cannot give step > 0) */
        lam += step;
        phi = ray_phi(K, mu, lam, &tx, &ty, &tMt);
    }
    double n = sqrt(phi);
    *rx = tx / n;
    *ry = ty / n;
    return 1;
}

pd_status pd_impact_diverging_ray(const double K[3][3], double mu, double *theta)
{
    double rx, ry;
    if (!pd_ray_diverging(K, mu, &rx, &ry))
        return PD_ERR_NO_CONVERGENCE;
    *theta = atan2(ry, rx);
    return PD_OK;
}

/* --- incoming rays ------------------------------------------------------------ *
 * A ray at angle th is invariant when the turning rate n.v vanishes
 * (n = (-sin th, cos th)):
 *   g(th) = A cos th + C sin th + D cos 2th + E sin 2th,
 *   A = a_y, C = -a_x, D = -mu B_xy, E = mu (B_xx - B_yy) / 2,
 * a trigonometric polynomial of degree 2, so at most 4 rays. With
 * t = tan((th - th0) / 2), (1 + t^2)^2 g is a quartic P(t) whose leading
 * coefficient is g(th0 + pi); th0 is picked among 8 directions so that this is
 * the largest, which keeps every root at a moderate t (the 8 samples bound
 * the polynomial's size, so g cannot be small at all of them). P is monotone
 * between its critical points, the roots of the cubic P' (closed form), so
 * each sign change there brackets exactly one root, found by Newton kept
 * inside the bracket: the roots to round-off, where a scan of th found them
 * only to its spacing and missed pairs closer than it. */

enum { ROOT_ITER = 100 };

/* P(t) = p[4] t^4 + ... + p[0] and P'(t). */
static double quartic(const double p[5], double t, double *dp)
{
    *dp = ((4.0 * p[4] * t + 3.0 * p[3]) * t + 2.0 * p[2]) * t + p[1];
    return (((p[4] * t + p[3]) * t + p[2]) * t + p[1]) * t + p[0];
}

/* The root of P in (lo, hi), where P is monotone, P(lo) = flo and P(hi) = fhi
 * of the other sign: Newton from the secant's root, bisecting whenever a step
 * would leave the bracket or fails to halve the one before, until its
 * correction falls below round-off. */
static double bracketed_root(const double p[5], double lo, double hi, double flo, double fhi)
{
    double x = lo + (hi - lo) * (flo / (flo - fhi)), dx_old = hi - lo;
    if (!(x > lo && x < hi))
        x = 0.5 * (lo + hi);
    for (int i = 0; i < ROOT_ITER; i++) {
        double d, f = quartic(p, x, &d);
        if (f == 0.0)
            return x;
        if ((f > 0.0) == (flo > 0.0))
            lo = x;
        else
            hi = x;
        double step = f / d;
        if (fabs(step) <= 2.0 * DBL_EPSILON * fabs(x))
            return x; /* converged to round-off */
        double nx = x - step;
        if (!(nx > lo && nx < hi) || fabs(step) > 0.5 * dx_old)
            nx = 0.5 * (lo + hi);
        dx_old = fabs(nx - x);
        if (!(hi - lo > 2.0 * DBL_EPSILON * fabs(nx)))
            return nx;
        x = nx;
    }
    return x;
}

void pd_rays_incoming(const double K[][3], double mu, pd_rays *in)
{
    in->n = 0;
    const double A = K[1][2], C = -K[0][2], D = -mu * K[0][1], E = 0.5 * mu * (K[0][0] - K[1][1]);
    /* th0 = k pi / 4: cos, sin of th0 and 2 th0, exactly where they can be. */
    const double r = 0.70710678118654752440;
    const double c1[8] = {1, r, 0, -r, -1, -r, 0, r}, s1[8] = {0, r, 1, r, 0, -r, -1, -r};
    const double c2[8] = {1, 0, -1, 0, 1, 0, -1, 0}, s2[8] = {0, 1, 0, -1, 0, 1, 0, -1};
    int k0 = 0;
    double gmax = 0.0;
    for (int k = 0; k < 8; k++) {
        double g = fabs(-A * c1[k] - C * s1[k] + D * c2[k] + E * s2[k]); /* g(th0 + pi) */
        if (g > gmax)
            gmax = g, k0 = k;
    }
    if (!(gmax > 0.0))
        return; /* g = 0: no direction turns */
    /* g in psi = th - th0, then P(tan(psi / 2)). */
    double Ar = A * c1[k0] + C * s1[k0], Cr = C * c1[k0] - A * s1[k0];
    double Dr = D * c2[k0] + E * s2[k0], Er = E * c2[k0] - D * s2[k0];
    const double p[5] = {Ar + Dr, 2.0 * Cr + 4.0 * Er, -6.0 * Dr, 2.0 * Cr - 4.0 * Er, Dr - Ar};
    /* Every root, and so every critical point, lies within Cauchy's bound. */
    double bound = 0.0;
    for (int i = 0; i < 4; i++)
        bound = fmax(bound, fabs(p[i] / p[4]));
    bound += 1.0;
    double ends[5];
    int nends = 0;
    ends[nends++] = -bound;
    double crit[3];
    int ncrit = pd_gsl_cubic_roots(0.75 * p[3] / p[4], 0.5 * p[2] / p[4], 0.25 * p[1] / p[4], crit);
    for (int i = 0; i < ncrit; i++)
        if (crit[i] > ends[nends - 1] && crit[i] < bound)
            ends[nends++] = crit[i];
    ends[nends++] = bound;
    double d, flo = quartic(p, ends[0], &d);
    for (int i = 0; i + 1 < nends; i++) {
        double fhi = quartic(p, ends[i + 1], &d);
        if (flo != 0.0 && fhi != 0.0 && (flo > 0.0) != (fhi > 0.0)) {
            double t = bracketed_root(p, ends[i], ends[i + 1], flo, fhi);
            double cp = (1.0 - t * t) / (1.0 + t * t), sp = 2.0 * t / (1.0 + t * t);
            double tx = c1[k0] * cp - s1[k0] * sp, ty = s1[k0] * cp + c1[k0] * sp;
            double vx = K[0][2] - mu * (K[0][0] * tx + K[0][1] * ty);
            double vy = K[1][2] - mu * (K[1][0] * tx + K[1][1] * ty);
            double rate = tx * vx + ty * vy;
            if (rate < 0.0) {
                in->tx[in->n] = tx;
                in->ty[in->n] = ty;
                in->rate[in->n] = rate;
                in->n++;
            }
        }
        flo = fhi;
    }
}

/* --- the diverging ray's basin ----------------------------------------------- *
 * The slip's direction turns at the rate g above (in tau, impact_slide.c),
 * whose roots are the invariant rays; between two roots it moves one way.
 * At phi = phi_d + psi (phi_d the diverging ray's angle), with
 * t = tan(psi / 2), (1 + t^2)^2 g = t Q(t) (g vanishes on the ray), Q a
 * cubic with Q(0) = 2 g'(phi_d) < 0 since the ray attracts. The direction is in the basin when Q < 0 from 0 to its
 * own t: at both ends and at Q's critical points between, each by
 * PD_TOL_IMPACT_BASIN_REL of the size of Q's terms, so that round-off
 * cannot pass a root. */
int pd_ray_in_basin(const double K[][3], double mu, double rtx, double rty, pd_vec3 u, double s)
{
    const double A = K[1][2], C = -K[0][2], D = -mu * K[0][1],
                 E = 0.5 * mu * (K[0][0] - K[1][1]);
    const double c1 = rtx, s1 = rty, c2 = c1 * c1 - s1 * s1, s2 = 2.0 * s1 * c1;
    const double Ar = A * c1 + C * s1, Cr = C * c1 - A * s1;
    const double Dr = D * c2 + E * s2, Er = E * c2 - D * s2;
    const double q[4] = {2.0 * Cr + 4.0 * Er, -6.0 * Dr, 2.0 * Cr - 4.0 * Er, Dr - Ar};
    const double t0 = (rtx * u.y - rty * u.x) / (s + u.x * rtx + u.y * rty);
    if (!isfinite(t0))
        return 0;
    double ts[4] = {0.0, t0, NAN, NAN};
    /* Q' = q1 + 2 q2 t + 3 q3 t^2, its roots in the form that does not cancel */
    const double disc = q[2] * q[2] - 3.0 * q[1] * q[3];
    if (disc >= 0.0) {
        const double qq = -(q[2] + copysign(sqrt(disc), q[2]));
        ts[2] = qq / (3.0 * q[3]);
        ts[3] = q[1] / qq;
    }
    const double lo = fmin(0.0, t0), hi = fmax(0.0, t0);
    for (int i = 0; i < 4; i++) {
        const double t = ts[i];
        if (i >= 2 && !(t > lo && t < hi))
            continue; /* outside, or none (NaN, infinite) */
        const double val = ((q[3] * t + q[2]) * t + q[1]) * t + q[0];
        const double size = ((fabs(q[3]) * fabs(t) + fabs(q[2])) * fabs(t) + fabs(q[1])) * fabs(t) + fabs(q[0]);
        if (!(val < -PD_TOL_IMPACT_BASIN_REL * size))
            return 0;
    }
    return 1;
}
