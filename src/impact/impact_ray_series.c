/* impact_ray_series.c: the slide's tail onto an incoming ray as a power
 * series in the angle to it (see impact_ray_series.h).
 *
 * In tau, u_t' = s a - mu B u_t (a = K_tz, B = K_tt). With u_t = s t(phi),
 * t = (cos phi, sin phi), n = (-sin phi, cos phi):
 *   phi' = b(phi) = n.a - mu n.B t,   (ln s)' = c(phi) = t.a - mu t.B t,
 * both independent of s. Along a trajectory d(s G(phi))/dtau = -s exactly
 * when b G' + c G = -1; the solution regular at the ray is the normal
 * impulse left to the origin divided by s, since s G -> 0 there. With
 * b = sum b_i delta^i (b_0 = 0: the ray is invariant), c = sum c_i delta^i,
 * the power delta^n of the equation reads
 *   (n b_1 + c_0) G_n = -[n = 0] - sum_{i=2..n} b_i (n - i + 1) G_{n-i+1}
 *                       - sum_{i=1..n} c_i G_{n-i},
 * and n b_1 + c_0 < 0 for every n when the ray attracts (b_1 < 0) and comes
 * in (c_0 < 0): no resonance, G_0 = 1 / |c_0|. The tangential impulse then
 * follows from u_t = 0 at the end: B dp_t = -(u_t + a dpz).
 *
 * The normal work: from any point on, the impulse left gives
 * u_z = u_z,end + s h(phi), h = w.t + (w.a - K_zz) G with w = B^-1 a, so the
 * work left is u_z,end dpz + s^2 F(phi), with b F' + 2 c F = -h, F's series
 * by the same recursion (2 c for c, -h_n for -[n = 0]). */
#include <math.h>
#include "impact/impact_ray_series.h"
#include "base/vec3.h"

enum { N = PD_RAY_SERIES_N, NO = PD_RAY_OUT_N };

/* Taylor coefficients in delta of C0 + A1 cos phi + S1 sin phi + A2 cos 2phi
 * + S2 sin 2phi at phi = phi* + delta, (c1, s1) = (cos, sin) phi*. */
static void trig_series(double C0, double A1, double S1, double A2, double S2, double c1,
                        double s1, double out[], int nt)
{
    const double c2 = c1 * c1 - s1 * s1, s2 = 2.0 * s1 * c1;
    const double P1 = A1 * c1 + S1 * s1, Q1 = S1 * c1 - A1 * s1;
    const double P2 = A2 * c2 + S2 * s2, Q2 = S2 * c2 - A2 * s2;
    double fact = 1.0, two = 1.0; /* 1 / n!, 2^n */
    for (int n = 0; n <= nt; n++) {
        const double sign = (n & 2) ? -1.0 : 1.0;
        out[n] = sign * fact * ((n & 1) ? Q1 + Q2 * two : P1 + P2 * two);
        fact /= n + 1;
        two *= 2.0;
    }
    out[0] += C0;
}

/* The regular solution of b X' + k c X = -rhs as a series (k = 1 or 2);
 * n b_1 + k c_0 < 0 for every n (the caller's test). */
static void solve_series(const double b[], const double c[], double k, const double rhs[],
                         double x[], int nt)
{
    for (int n = 0; n <= nt; n++) {
        double sum = -rhs[n];
        for (int i = 2; i <= n; i++)
            sum -= b[i] * (n - i + 1) * x[n - i + 1];
        for (int i = 1; i <= n; i++)
            sum -= k * c[i] * x[n - i];
        x[n] = sum / (n * b[1] + k * c[0]);
    }
}

/* The turning rate b and the growth rate c of the slip's direction
 * phi = phi* + delta as series in delta at the invariant ray (tx, ty). */
static void ray_rates(const double K[][3], double mu, double tx, double ty, double b[],
                      double c[], int nt)
{
    const double ax = K[0][2], ay = K[1][2], bxx = K[0][0], bxy = K[0][1], byy = K[1][1];
    trig_series(0.0, ay, -ax, -mu * bxy, -0.5 * mu * (byy - bxx), tx, ty, b, nt);
    trig_series(-0.5 * mu * (bxx + byy), ax, ay, -0.5 * mu * (bxx - byy), -mu * bxy, tx, ty, c, nt);
    b[0] = 0.0; /* the ray's round-off: a b_0 would couple every order to the next */
}

void pd_ray_series_build(const double K[][3], double mu, double tx, double ty, int with_work,
                         pd_ray_series *sr)
{
    const double ax = K[0][2], ay = K[1][2], bxx = K[0][0], bxy = K[0][1], byy = K[1][1];
    double b[N + 1], c[N + 1], rhs[N + 1] = {1.0};
    ray_rates(K, mu, tx, ty, b, c, N);
    sr->tx = tx;
    sr->ty = ty;
    sr->ok = b[1] < 0.0 && c[0] < 0.0;
    if (!sr->ok)
        return;
    solve_series(b, c, 1.0, rhs, sr->g, N);
    const double det = bxx * byy - bxy * bxy;
    sr->wx = (byy * ax - bxy * ay) / det;
    sr->wy = (bxx * ay - bxy * ax) / det;
    if (!with_work)
        return;
    trig_series(0.0, sr->wx, sr->wy, 0.0, 0.0, tx, ty, rhs, N);
    const double schur = sr->wx * ax + sr->wy * ay - K[2][2];
    for (int n = 0; n <= N; n++)
        rhs[n] += schur * sr->g[n];
    solve_series(b, c, 2.0, rhs, sr->f, N);
}

/* The series x at delta, and in *err its last two terms' size: with delta
 * within half the radius of convergence the rest is below that. The radius
 * by the root test: the series at 2 delta has no term in the upper half
 * larger than the largest of the lower half (which still carries the
 * leading terms' sizes); *err is infinite where that fails. */
static double series_at(const double x[], double delta, double *err)
{
    double sum = 0.0, pw = 1.0, pw2 = 1.0, last = 0.0, low = 0.0;
    *err = 0.0;
    for (int n = 0; n <= N; n++, pw *= delta, pw2 *= 2.0 * delta) {
        sum += x[n] * pw;
        const double a2 = fabs(x[n] * pw2);
        if (n < N / 2)
            low = a2 > low ? a2 : low;
        else if (a2 > low)
            *err = INFINITY;
        if (n == N)
            *err += last + fabs(x[n] * pw);
        last = fabs(x[n] * pw);
    }
    return sum;
}

/* q = du_z/dpz = K_zz - mu a.t along the arc from the ray to delta: a
 * cosine in phi, so its least is at an end or at the direction of a. */
static int rises_along(const double K[][3], double mu, double tx, double ty, double delta,
                       pd_vec3 u, double s)
{
    const double ax = K[0][2], ay = K[1][2];
    if (!(K[2][2] - mu * (ax * tx + ay * ty) > 0.0) ||
        !(K[2][2] - mu * (ax * u.x + ay * u.y) / s > 0.0))
        return 0;
    double na = hypot(ax, ay);
    if (K[2][2] - mu * na > 0.0)
        return 1;
    double dm = atan2(tx * ay - ty * ax, tx * ax + ty * ay);
    return !(dm * delta > 0.0 && fabs(dm) <= fabs(delta));
}

int pd_ray_series_tail(const double K[][3], double mu, const pd_ray_series *sr, pd_vec3 u,
                       double max_angle, double max_err, int with_work, pd_vec3 *dp, double *dw)
{
    const double dot = u.x * sr->tx + u.y * sr->ty, crs = sr->tx * u.y - sr->ty * u.x;
    if (!sr->ok || !(dot > 0.0) || !(fabs(crs) <= max_angle * dot))
        return 0; /* cheap refusal first: asked at every step near the origin */
    const double delta = atan2(crs, dot), s = hypot(u.x, u.y);
    double eg, G = series_at(sr->g, delta, &eg);
    const double wn = hypot(sr->wx, sr->wy);
    double err = s * eg * (1.0 + wn);
    if (!(err <= max_err) || !rises_along(K, mu, sr->tx, sr->ty, delta, u, s))
        return 0;
    const double pz = s * G;
    const double bxx = K[0][0], bxy = K[0][1], byy = K[1][1], det = bxx * byy - bxy * bxy;
    const double vx = (byy * u.x - bxy * u.y) / det, vy = (bxx * u.y - bxy * u.x) / det;
    const double px = -vx - sr->wx * pz, py = -vy - sr->wy * pz;
    double work = 0.0;
    if (with_work) {
        double ef, F = series_at(sr->f, delta, &ef);
        double uzf = u.z + K[2][0] * px + K[2][1] * py + K[2][2] * pz;
        double duz = (hypot(K[2][0], K[2][1]) * wn + K[2][2]) * s * eg;
        err = fmax(err, s * eg * fabs(uzf) + duz * pz + s * s * ef);
        if (!(err <= max_err))
            return 0;
        work = uzf * pz + s * s * F;
    }
    *dp = v3(px, py, pz);
    *dw = work;
    return 1;
}

/* --- the diverging ray ------------------------------------------------------
 *
 * With b = delta beta(delta), c/b = Q(delta)/delta, Q = c/beta, Q_0 = -nu:
 * d/dtau [ln s + nu ln|delta| - R(delta)] = c + nu b/delta - R' b = 0 for
 * R' = (Q - Q_0)/delta, R = sum_{n>=1} Q_n delta^n / n. And d(s H)/dtau =
 * s (c H + b H') = s = dpz/dtau. So from (s, delta) to delta_e further on
 * (|delta_e| < |delta|, the same sign: |delta| only falls, beta < 0):
 *   ln s_e = ln s + nu (ln|delta| - ln|delta_e|) + R(delta_e) - R(delta),
 *   dpz = s_e H(delta_e) - s H(delta),   u_t,e = s_e t(phi* + delta_e),
 * the tangential impulse from u_t,e = u_t + B dp_t + a dpz, and u_z,e =
 * u_z + w.(u_t,e - u_t) + (K_zz - w.a) dpz, w = B^-1 a. Along the way
 * dpz/d ln|delta_e| = s_e / beta(delta_e) and du_z/dpz = K_zz - mu K_zt.t. */

void pd_ray_out_build(const double K[][3], double mu, double tx, double ty, pd_ray_out *o)
{
    double b[NO + 1], c[NO + 1], rhs[NO + 1] = {-1.0};
    ray_rates(K, mu, tx, ty, b, c, NO);
    o->tx = tx;
    o->ty = ty;
    o->ok = b[1] < 0.0 && c[0] > 0.0;
    if (!o->ok)
        return;
    o->nu = c[0] / -b[1];
    solve_series(b, c, 1.0, rhs, o->h, NO); /* b H' + c H = 1 */
    for (int n = 0; n < NO; n++)
        o->beta[n] = b[n + 1];
    o->beta[NO] = 0.0; /* b's series stops at delta^NO */
    double q[NO];
    for (int n = 0; n < NO; n++) {
        double sum = c[n];
        for (int i = 1; i <= n; i++)
            sum -= o->beta[i] * q[n - i];
        q[n] = sum / o->beta[0];
    }
    o->r[0] = 0.0;
    for (int n = 1; n < NO; n++)
        o->r[n] = q[n] / n;
    o->r[NO] = 0.0;
    const double ax = K[0][2], ay = K[1][2], bxx = K[0][0], bxy = K[0][1], byy = K[1][1];
    const double det = bxx * byy - bxy * bxy;
    o->wx = (byy * ax - bxy * ay) / det;
    o->wy = (bxx * ay - bxy * ax) / det;
    for (int n = 0; n <= NO; n++)
        o->ok &= isfinite(o->h[n]) && isfinite(o->r[n]);
}

/* A series of the diverging ray's tail at delta, x[0..m]: its sum, and in
 * *err the sum of its last four terms' sizes, infinite unless delta is
 * within half the radius of convergence (series_at's root test). Not the
 * last two terms' as series_at: a term can dip far below its neighbours
 * (measured: H's 12th term 4e-4 of the 10th where the 14th was 5e-2 of
 * it, on a cap's impact whose tail then missed by 3e-9 of |u0|, its two
 * terms claiming 6e-12), and with K_tz = 0 (a contact below the centre of
 * mass's axis) the series are even, every other term zero. */
static double out_series(const double x[], int m, double delta, double *err)
{
    double sum = 0.0, pw = 1.0, pw2 = 1.0, low = 0.0, tail = 0.0;
    int wide = 0;
    for (int n = 0; n <= m; n++, pw *= delta, pw2 *= 2.0 * delta) {
        sum += x[n] * pw;
        const double a2 = fabs(x[n] * pw2);
        if (2 * n < m)
            low = a2 > low ? a2 : low;
        else if (a2 > low)
            wide = 1;
        if (n > m - 4)
            tail += fabs(x[n] * pw);
    }
    *err = wide ? (double)INFINITY : tail;
    return sum;
}

/* Iterations allowed to the tail's root: it takes 1-4 where the series
 * hold (measured on the recorded drops); more means a root the round-off
 * of the series' sums cannot resolve, and the slide is stepped instead. */
#define OUT_NEWTON_MAX 8

/* The tail lands on its event within this share of the event tolerance:
 * the steps it replaces land on theirs to round-off (a step in the event's
 * own variable), and landing within the whole tolerance doubled the worst
 * impulse error on the recorded drops' impacts (3.4e-9 against 1.3e-9 of
 * |u0|/K); Newton converges quadratically, so this costs an iteration at
 * most. */
#define OUT_LAND 1e-3

/* The end of the way at x = ln|delta_e|: the slip and its direction, the
 * normal impulse gained, and its rate in x. */
typedef struct {
    double s, tx, ty, dpz, dpz_dx, eh, er, H;
} out_point;

static int out_at(const pd_ray_out *o, double sgn, double x, double lns0, out_point *e)
{
    const double d = sgn * exp(x);
    double eb, R = out_series(o->r, NO - 1, d, &e->er);
    e->H = out_series(o->h, NO, d, &e->eh);
    const double be = out_series(o->beta, NO - 1, d, &eb);
    e->s = exp(lns0 - o->nu * x + R);
    double sd, cd;
    sd = sin(d), cd = cos(d);
    e->tx = o->tx * cd - o->ty * sd;
    e->ty = o->ty * cd + o->tx * sd;
    e->dpz = e->s * e->H;
    e->dpz_dx = e->s / be;
    return isfinite(e->dpz) && isfinite(e->dpz_dx) && be < 0.0;
}

int pd_ray_out_tail(const double K[][3], double mu, const pd_ray_out *o, pd_vec3 u, int target,
                    double goal, double ev_tol, double max_angle, double max_err, pd_vec3 *dp)
{
    const double dot = u.x * o->tx + u.y * o->ty, crs = o->tx * u.y - o->ty * u.x;
    if (!o->ok || !(dot > 0.0) || !(fabs(crs) <= max_angle * dot) || crs == 0.0)
        return 0; /* cheap refusal first; on the ray itself the slide's closed form */
    const double delta = atan2(crs, dot), s = hypot(u.x, u.y), sgn = delta > 0.0 ? 1.0 : -1.0;
    if (target == PD_RAY_OUT_COMPRESS && !(u.z < 0.0 && rises_along(K, mu, o->tx, o->ty, delta, u, s)))
        return 0;
    if (target == PD_RAY_OUT_PZ && !(goal > 0.0))
        return 0;
    const double x0 = log(fabs(delta));
    double eh0, er0, R0 = out_series(o->r, NO - 1, delta, &er0), H0 = out_series(o->h, NO, delta, &eh0);
    if (!isfinite(eh0 + er0))
        return 0; /* beyond half the radius of convergence */
    const double lns0 = log(s) + o->nu * x0 - R0, pz0 = s * H0;
    const double kappa = K[2][2] - (o->wx * K[0][2] + o->wy * K[1][2]);
    const double bxx = K[0][0], bxy = K[0][1], byy = K[1][1], det = bxx * byy - bxy * bxy;
    const double wn = 1.0 + hypot(o->wx, o->wy);
    /* The error bound below, before the root is sought: at the end s_e H
     * is pz0 plus the impulse still to come, at least its first-order
     * estimate (u_z rises at most at K_zz + mu |K_zt| per unit of it). */
    const double least = target == PD_RAY_OUT_PZ ? goal : -u.z / (K[2][2] + mu * hypot(K[2][0], K[2][1]));
    if (!((s * eh0 + fmax(pz0 + least, 0.0) * er0) * wn <= max_err))
        return 0;
    /* The event's function f falls along the way (as x falls), f(x0) < 0.
     * It is close to linear in the normal impulse (u_z rises at q per unit
     * of it), and ln(pz0 + dpz) = ln(s_e H(delta_e)) close to linear in x
     * (slope -nu, plus what delta_e still changes): each iteration is a
     * Newton step in the impulse, taken to x by one in that logarithm,
     * safeguarded by the bracket [lo, hi] in x (f > 0 at lo). */
    double x = x0, lo = -INFINITY, hi = x0, f = 0.0;
    out_point e;
    int it = 0;
    for (; it < OUT_NEWTON_MAX; it++) {
        if (!out_at(o, sgn, x, lns0, &e))
            return 0;
        const double dpz = e.dpz - pz0;
        double rate = 1.0; /* df / d dpz */
        if (target == PD_RAY_OUT_COMPRESS) {
            f = u.z + o->wx * (e.s * e.tx - u.x) + o->wy * (e.s * e.ty - u.y) + kappa * dpz;
            rate = K[2][2] - mu * (K[2][0] * e.tx + K[2][1] * e.ty);
        } else {
            f = dpz - goal;
        }
        if (fabs(f) <= OUT_LAND * ev_tol)
            break;
        if (f > 0.0)
            lo = x;
        else
            hi = x;
        const double want = e.dpz - f / rate; /* pz0 + dpz wanted, to first order */
        double xn = NAN;
        if (e.dpz > 0.0 && want > 0.0)
            xn = x + log(want / e.dpz) * e.H * (e.s / e.dpz_dx); /* d ln(s_e H)/dx = 1 / (beta H) */
        if (!(xn > lo && xn < hi))
            xn = isfinite(lo) ? 0.5 * (lo + hi) : hi - 2.0 * (hi - x + 1.0);
        x = xn;
    }
    if (it == OUT_NEWTON_MAX)
        return 0;
    /* Errors: the series' truncations at both ends; R's is relative in s_e. */
    const double erel = er0 + e.er;
    const double epz = s * eh0 + e.s * (e.eh + fabs(e.H) * erel);
    const double err = epz * wn + (bxx + byy) / det * e.s * erel;
    if (!(err <= max_err))
        return 0;
    const double dpz = e.dpz - pz0;
    const double dux = e.s * e.tx - u.x, duy = e.s * e.ty - u.y;
    /* B dp_t = du_t - a dpz */
    const double rx = dux - K[0][2] * dpz, ry = duy - K[1][2] * dpz;
    *dp = v3((byy * rx - bxy * ry) / det, (bxx * ry - bxy * rx) / det, dpz);
    return v3_isfinite(*dp);
}
