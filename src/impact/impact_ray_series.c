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

enum { N = PD_RAY_SERIES_N };

/* Taylor coefficients in delta of C0 + A1 cos phi + S1 sin phi + A2 cos 2phi
 * + S2 sin 2phi at phi = phi* + delta, (c1, s1) = (cos, sin) phi*. */
static void trig_series(double C0, double A1, double S1, double A2, double S2, double c1,
                        double s1, double out[N + 1])
{
    const double c2 = c1 * c1 - s1 * s1, s2 = 2.0 * s1 * c1;
    const double P1 = A1 * c1 + S1 * s1, Q1 = S1 * c1 - A1 * s1;
    const double P2 = A2 * c2 + S2 * s2, Q2 = S2 * c2 - A2 * s2;
    double fact = 1.0, two = 1.0; /* 1 / n!, 2^n */
    for (int n = 0; n <= N; n++) {
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
                         double x[N + 1])
{
    for (int n = 0; n <= N; n++) {
        double sum = -rhs[n];
        for (int i = 2; i <= n; i++)
            sum -= b[i] * (n - i + 1) * x[n - i + 1];
        for (int i = 1; i <= n; i++)
            sum -= k * c[i] * x[n - i];
        x[n] = sum / (n * b[1] + k * c[0]);
    }
}

void pd_ray_series_build(const double K[][3], double mu, double tx, double ty, int with_work,
                         pd_ray_series *sr)
{
    const double ax = K[0][2], ay = K[1][2], bxx = K[0][0], bxy = K[0][1], byy = K[1][1];
    double b[N + 1], c[N + 1], rhs[N + 1] = {1.0};
    trig_series(0.0, ay, -ax, -mu * bxy, -0.5 * mu * (byy - bxx), tx, ty, b);
    trig_series(-0.5 * mu * (bxx + byy), ax, ay, -0.5 * mu * (bxx - byy), -mu * bxy, tx, ty, c);
    b[0] = 0.0; /* the ray's round-off: a b_0 would couple every order to the next */
    sr->tx = tx;
    sr->ty = ty;
    sr->ok = b[1] < 0.0 && c[0] < 0.0;
    if (!sr->ok)
        return;
    solve_series(b, c, 1.0, rhs, sr->g);
    const double det = bxx * byy - bxy * bxy;
    sr->wx = (byy * ax - bxy * ay) / det;
    sr->wy = (bxx * ay - bxy * ax) / det;
    if (!with_work)
        return;
    trig_series(0.0, sr->wx, sr->wy, 0.0, 0.0, tx, ty, rhs);
    const double schur = sr->wx * ax + sr->wy * ay - K[2][2];
    for (int n = 0; n <= N; n++)
        rhs[n] += schur * sr->g[n];
    solve_series(b, c, 2.0, rhs, sr->f);
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
static int rises_along(const double K[][3], double mu, const pd_ray_series *sr, double delta,
                       pd_vec3 u, double s)
{
    const double ax = K[0][2], ay = K[1][2];
    if (!(K[2][2] - mu * (ax * sr->tx + ay * sr->ty) > 0.0) ||
        !(K[2][2] - mu * (ax * u.x + ay * u.y) / s > 0.0))
        return 0;
    double na = hypot(ax, ay);
    if (K[2][2] - mu * na > 0.0)
        return 1;
    double dm = atan2(sr->tx * ay - sr->ty * ax, sr->tx * ax + sr->ty * ay);
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
    if (!(err <= max_err) || !rises_along(K, mu, sr, delta, u, s))
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
