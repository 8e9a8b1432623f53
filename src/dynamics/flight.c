/* flight.c: torque-free flight in closed form (see flight.h).
 *
 * Method. The world angular momentum L is constant; u = L/|L| in the body frame
 * obeys Euler's equations du/dt = |L| u x (J u), J = diag(1/I). Two integrals,
 * |u| = 1 and u.J u = 2T/|L|^2 = D, make u move on a polhode, solved by Jacobi
 * elliptic functions (Landau & Lifshitz, Mechanics, sec. 37; our own
 * derivation in the notation below). In a "chart" frame (a signed permutation
 * of the principal axes) in which the polhode circles chart axis 3 with
 * u3 > 0 and D lies between J3 and J2:
 *   u1 = a1 cn(tau), u2 = a2 sn(tau), u3 = a3 dn(tau), tau = tau0 + Omega t,
 *   a1^2 = (D-J3)/(J1-J3), a2^2 = (D-J3)/(J2-J3), a3^2 = (J1-D)/(J1-J3),
 *   m = (J1-J2)(D-J3) / ((J2-J3)(J1-D)),
 *   Omega = sign(J2-J3) |L| sqrt(|J2-J3| |J1-D|).
 * The orientation uses Euler angles (z-x-z) about L: chart -> L-frame is
 * Rz(phi) Rx(theta) Rz(psi), where theta and psi follow from u and
 *   dphi/dt = |L| (J1 u1^2 + J2 u2^2)/(u1^2 + u2^2)
 *           = |L| (J3 + (J1-J3)/(1 + n sn^2 tau)),  n = (J1-J2)/(J2-J3),
 * whose integral is Legendre's incomplete integral of the third kind. Both
 * forms hold for J1 > J2 > J3 and for J1 < J2 < J3 (all the ratios above are
 * then positive). Conservation is by construction: the world angular
 * momentum is R(t) |L| u(t) = Q0 Rz(phi) |L| z = L for any phi, and the energy
 * is |L|^2 u.J u / 2 = |L|^2 D / 2 since the elliptic functions satisfy
 * sn^2 + cn^2 = 1 and dn^2 + m sn^2 = 1 to round-off (the theta series: to
 * 1e-11 closest to the separatrix, see PD_FLIGHT_NOME_MAX).
 *
 * Evaluation. Off the separatrix (nome q <= PD_FLIGHT_NOME_MAX) by Jacobi's
 * theta series, planned once per flight (flight_theta.c): there phi = rate t
 * + arg Y(v) - arg Y(v0), the constant part taken into Q0, and only e^(i
 * phi/2) is needed, so an evaluation takes two sincos and a few series
 * terms. On the separatrix itself (m = 1 in double precision), where the
 * series would converge slowly and cancel, by GSL's sn, cn, dn and
 * Legendre's integrals. Either way the quaternion is built from u, the
 * unnormalised Y (or 1) and e^(i rate t/2) by half-angle formulas
 * (chart_rotation), with no arc tangent. */
#include <math.h>
#include <stddef.h>
#include <string.h>
#include "dynamics/flight.h"
#include "base/gsl_adapter.h"
#include "dynamics/dynamics_tol.h"
#include "base/sincos.h"
#include "base/vec3.h"

static const double PI = 3.14159265358979323846;

static pd_vec3 body_L(const pd_body *b, pd_vec3 w)
{
    return v3(b->moment[0] * w.x, b->moment[1] * w.y, b->moment[2] * w.z);
}

static double comp(pd_vec3 v, int i) { return i == 0 ? v.x : i == 1 ? v.y : v.z; }

/* e^(i a/2), a = arg(x + i y) in (-pi, pi], (x, y) != 0 of any length,
 * without trigonometry: the half-angle formulas, each on the side where it
 * has no cancellation. */
static void half_angle(double x, double y, double *hc, double *hs)
{
    double r = sqrt(x * x + y * y);
    if (x >= 0.0) {
        *hc = sqrt(0.5 * (1.0 + x / r));
        *hs = y / (2.0 * r * *hc);
    } else {
        *hs = copysign(sqrt(0.5 * (1.0 - x / r)), y);
        *hc = y / (2.0 * r * *hs);
    }
}

/* Chart -> L-frame rotation Rz(phi) Rx(theta) Rz(psi) as a quaternion, with
 * theta and psi the chart angles of u (u = Rz(psi)^T Rx(theta)^T z / |u|:
 * theta = atan2(|u1, u2|, u3), psi = atan2(u1, u2)), u3 >= 0 (the chart's
 * u3 is a3 dn), and phi = arg z + 2 a given as z (any length) and e^(i a)
 * = ac + i as. The product of the three half-angle rotations is
 *   w + i z = cos(theta/2) A,  x + i y = sin(theta/2) A e^(-i psi),
 *   A = e^(i (phi + psi)/2),
 * and A is e^(i a) times the half angle of z (u2 + i u1), whose argument is
 * phi - 2a + psi: one square root for both half angles, and sin(theta/2)
 * e^(-i psi) = (u2 - i u1) / (2 |u| cos(theta/2)) needs none. The half
 * angle's branch only picks the quaternion's sign. Nothing here is an arc
 * tangent or a sine. */
static pd_quat chart_rotation(const double u[3], double zr, double zi, double ac, double as)
{
    double rho2 = u[0] * u[0] + u[1] * u[1];
    double r = sqrt(rho2 + u[2] * u[2]);
    double ct = sqrt(0.5 * (1.0 + u[2] / r)); /* cos theta/2 */
    double k = 1.0 / (2.0 * r * ct);          /* sin(theta/2) / |u1, u2| */
    double pr = zr, pi = zi;                  /* psi = 0 on the axis itself */
    if (rho2 > 0.0) {
        pr = zr * u[1] - zi * u[0];
        pi = zr * u[0] + zi * u[1];
    }
    double hc, hs;
    half_angle(pr, pi, &hc, &hs);
    double Ar = ac * hc - as * hs, Ai = as * hc + ac * hs;
    return quat(ct * Ar, k * (Ar * u[1] + Ai * u[0]), k * (Ai * u[1] - Ar * u[0]), ct * Ai);
}

/* Elliptic state at argument tau: u in the chart, and the unrolled
 * P(am tau, k, n) (continuous in tau across periods). */
static pd_status elliptic_at(const pd_flight *f, double tau, double u[3], double *P)
{
    double j = 0.0;
    if (f->K2 > 0.0)
        j = nearbyint(tau / f->K2);
    double tr = tau - j * f->K2; /* in [-K, K]: am(tr) in [-pi/2, pi/2] */
    double sn, cn, dn, Pr;
    pd_status st = pd_elljac(tr, f->m, &sn, &cn, &dn);
    if (st != PD_OK)
        return st;
    double am = atan2(sn, cn);
    if ((st = pd_ellint_P(am, f->k, f->n, &Pr)) != PD_OK)
        return st;
    /* sn and cn change sign with each half period 2K; dn does not. */
    double par = fmod(j, 2.0) != 0.0 ? -1.0 : 1.0;
    u[0] = f->alpha[0] * cn * par;
    u[1] = f->alpha[1] * sn * par;
    u[2] = f->alpha[2] * dn;
    *P = Pr + 2.0 * j * f->Pc;
    return PD_OK;
}

/* Signed permutation taking body axis c (sign s) to chart axis 3, as a proper
 * rotation: for c = 3 it is the identity or a half turn about x; for c = 1 a
 * quarter turn about y. */
static void set_chart(pd_flight *f, int c, double s)
{
    double E[3][3] = {{0}};
    if (c == 2) {
        f->perm[0] = 0, f->perm[1] = 1, f->perm[2] = 2;
        f->sgn[0] = 1.0, f->sgn[1] = s, f->sgn[2] = s;
        f->e_kind = s > 0.0 ? 0 : 1;
    } else {
        f->perm[0] = 2, f->perm[1] = 1, f->perm[2] = 0;
        f->sgn[0] = -s, f->sgn[1] = 1.0, f->sgn[2] = s;
        f->e_kind = 2;
    }
    for (int i = 0; i < 3; i++)
        E[i][f->perm[i]] = f->sgn[i];
    f->e = quat_from_matrix(CONST_M3(E));
}

/* quat_axis_angle by pd_sincos. */
static pd_quat turn(pd_vec3 axis, double angle)
{
    double s, c;
    pd_sincos(0.5 * angle, &s, &c);
    return quat(c, axis.x * s, axis.y * s, axis.z * s);
}

/* a e (quat_mul) without the products with e's zero components, which add
 * exactly nothing: the same result for a fraction of the work. */
static pd_quat times_e(const pd_flight *f, pd_quat a)
{
    double c = f->e.w, d = f->e.y;
    switch (f->e_kind) {
    case 0:
        return a;
    case 1:
        return quat(-a.x, a.w, a.z, -a.y);
    default:
        return quat(a.w * c - a.y * d, a.x * c - a.z * d, a.w * d + a.y * c, a.x * d + a.z * c);
    }
}

/* The principal axis u lies on within tol (its other components), or -1. */
static int principal_axis(pd_vec3 u, double tol)
{
    if (fabs(u.y) <= tol && fabs(u.z) <= tol)
        return 0;
    if (fabs(u.x) <= tol && fabs(u.z) <= tol)
        return 1;
    if (fabs(u.x) <= tol && fabs(u.y) <= tol)
        return 2;
    return -1;
}

/* omega = a u + b axis (flight.h): a spherical top or a spin about a
 * principal axis (on_axis >= 0) turns about L alone; a symmetric top also
 * about its distinct axis. */
static inline void set_axial(pd_flight *F, const double *I, const double *J, pd_vec3 u, int on_axis)
{
    F->kind = PD_FLIGHT_AXIAL;
    if (I[0] == I[2] || on_axis >= 0) {
        F->a = F->lambda * (on_axis >= 0 ? J[on_axis] : J[0]);
        F->b = 0.0;
        F->axis = v3(0.0, 0.0, 1.0);
    } else {
        int d = I[0] == I[1] ? 2 : 0; /* the distinct axis */
        int s = d == 2 ? 0 : 2;       /* one of the equal pair */
        F->axis = d == 2 ? v3(0.0, 0.0, 1.0) : v3(1.0, 0.0, 0.0);
        F->a = F->lambda * J[s];
        F->b = F->lambda * comp(u, d) * (J[d] - J[s]);
    }
}

/* The asymmetric top in closed form (header), u = L/|L| in the body frame. */
static pd_status plan_elliptic(pd_flight *F, pd_vec3 u, const double *J)
{
    /* Asymmetric: D - J2 without cancellation decides which axis the polhode
     * circles: the largest moment (body axis 3) when D < J2, else axis 1. */
    double ux = u.x, uz = u.z;
    double DmJ2 = (J[0] - J[1]) * ux * ux + (J[2] - J[1]) * uz * uz;
    int c = DmJ2 < 0.0 ? 2 : DmJ2 > 0.0 ? 0 : (fabs(uz) >= fabs(ux) ? 2 : 0);
    double uc = c == 2 ? uz : ux;
    set_chart(F, c, uc > 0.0 ? 1.0 : -1.0);
    double uch[3];
    for (int i = 0; i < 3; i++) {
        uch[i] = F->sgn[i] * comp(u, F->perm[i]);
        F->J[i] = J[F->perm[i]];
        F->wsc[i] = F->sgn[i] * F->lambda * F->J[i];
    }
    double J1 = F->J[0], J2 = F->J[1], J3 = F->J[2];
    /* D - J3 and J1 - D from the components: no cancellation near pure spin. */
    double DmJ3 = (J1 - J3) * uch[0] * uch[0] + (J2 - J3) * uch[1] * uch[1];
    double J1mD = (J1 - J2) * uch[1] * uch[1] + (J1 - J3) * uch[2] * uch[2];
    F->alpha[0] = sqrt(DmJ3 / (J1 - J3));
    F->alpha[1] = sqrt(DmJ3 / (J2 - J3));
    F->alpha[2] = sqrt(J1mD / (J1 - J3));
    F->m = (J1 - J2) * DmJ3 / ((J2 - J3) * J1mD);
    if (F->m > 1.0)
        F->m = 1.0; /* round-off on the separatrix */
    F->k = sqrt(F->m);
    F->n = (J1 - J2) / (J2 - J3);
    F->Omega = (J2 > J3 ? 1.0 : -1.0) * F->lambda * sqrt(fabs(J2 - J3) * fabs(J1mD));
    F->kind = PD_FLIGHT_ELLIPTIC;
    /* Q0 = q0 e^-1 B(0)^-1, B(0) from the actual u so that R(0) = q0 to
     * round-off, and with phi(0) as the evaluation has it (below, or 0). */
    pd_quat q0e = quat_mul(F->s0.q, quat_conj(F->e));
    /* The theta series where they converge fast (flight_theta.h), with
     * 1 - m = (J1 - J3)(J2 - D) / ((J2 - J3)(J1 - D)) free of cancellation.
     * phi = lambda (J3 t + (J1 - J3)(P(tau) - P(tau0)) / Omega), P = mu tau +
     * sigma arg X, and lambda (J1 - J3) sigma / Omega = 1 exactly (sigma^2 =
     * (J1 - D)(J2 - J3) / (J1 - J3)^2 from the header's ratios); arg X(v) =
     * arg Y(v) - v0 - nu t. So phi = rate t + arg Y(v) - arg Y(v0), the last
     * term a constant rotation about L that Q0 takes up. */
    double mc = (J1 - J3) * -DmJ2 / ((J2 - J3) * J1mD);
    if (pd_theta_plan(&F->th, F->m, mc, F->n, uch[1] / F->alpha[1], uch[0] / F->alpha[0],
                      F->Omega) == PD_OK) {
        double sn, cn, dn, y0[2];
        pd_theta_eval(&F->th, 0.0, &sn, &cn, &dn, y0);
        F->theta = 1;
        F->rate = F->lambda * (J3 + (J1 - J3) * F->th.mu) - F->th.nu;
        F->Q0 = quat_mul(q0e, quat_conj(chart_rotation(uch, y0[0], y0[1], 1.0, 0.0)));
        return PD_OK;
    }
    F->Q0 = quat_mul(q0e, quat_conj(chart_rotation(uch, 1.0, 0.0, 1.0, 0.0)));
    pd_status st;
    double K = 0.0;
    if (F->m < 1.0) {
        if ((st = pd_ellint_Kcomp(F->k, &K)) != PD_OK ||
            (st = pd_ellint_Pcomp(F->k, F->n, &F->Pc)) != PD_OK)
            return st;
        F->K2 = 2.0 * K;
    }
    /* Initial phase: cn = u1/a1, sn = u2/a2, so am(tau0) = atan2(u2/a2, u1/a1),
     * then tau0 = F(am) with half periods unrolled (F(am + j pi) = F(am) + 2jK). */
    double am0 = atan2(uch[1] / F->alpha[1], uch[0] / F->alpha[0]);
    double j0 = 0.0;
    if (am0 > 0.5 * PI)
        j0 = 1.0;
    else if (am0 < -0.5 * PI)
        j0 = -1.0;
    double Fr;
    if (F->m < 1.0 || j0 == 0.0) {
        if ((st = pd_ellint_F(am0 - j0 * PI, F->k, &Fr)) != PD_OK)
            return st;
    } else {
        return PD_ERR_NONFINITE; /* unreachable: on the separatrix cn > 0 */
    }
    F->tau0 = Fr + j0 * F->K2;
    double u0[3];
    return elliptic_at(F, F->tau0, u0, &F->P0);
}

/* A bound on |w| over the torque-free motion from body rates w0 (principal
 * moments I, |L|^2 = L2). Along the motion the squares x_i = w_i^2 keep
 * sum I_i x_i = 2 E and sum I_i^2 x_i = L2, so |w|^2 = sum x_i is at most
 * the largest sum over the vertices of that set with x >= 0, each with at
 * most two x_i nonzero (a linear programme's basic solutions). |L| / I_min,
 * the classical bound, can be looser by the inertia ratio: a needle 1000
 * times longer than thick turning end over end at 3 rad/s got a bound of
 * 1.6e6 rad/s, and the impact search, whose steps shrink with it, ran out
 * of steps. A pair of moments closer than PD_FLIGHT_WMAX_PAIR_REL is left
 * out (its solution is round-off; the set is then nearly a segment whose
 * ends the other pairs give), and the round-off of the others, at most
 * ~1e-16 (2 E / I_min) / PD_FLIGHT_WMAX_PAIR_REL, is covered by adding
 * PD_FLIGHT_WMAX_ROUND times 2 E / I_min. Never above the classical bounds. */
static inline double wmax_bound(const double *I, pd_vec3 w0, double L2)
{
    double w[3] = {w0.x, w0.y, w0.z}, E2 = 0.0, best = 0.0, Imin = fmin(I[0], fmin(I[1], I[2]));
    for (int i = 0; i < 3; i++) {
        E2 += I[i] * w[i] * w[i];
        best += w[i] * w[i];
    }
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++) {
            double d = I[i] - I[j];
            if (fabs(d) <= PD_FLIGHT_WMAX_PAIR_REL * fmax(I[i], I[j]))
                continue;
            double xi = (L2 - I[j] * E2) / (I[i] * d), xj = (L2 - I[i] * E2) / (-I[j] * d);
            if (xi >= 0.0 && xj >= 0.0)
                best = fmax(best, xi + xj);
        }
    double w2 = best + PD_FLIGHT_WMAX_ROUND * E2 / Imin;
    return fmin(sqrt(fmin(w2, E2 / Imin)), sqrt(L2) / Imin);
}

pd_status pd_flight_plan_bounds(const pd_body *b, const pd_state *s0, double g, pd_flight *f)
{
    if (!b || !s0 || !f || !(g >= 0.0))
        return PD_ERR_USAGE;
    if (!v3_isfinite(s0->x) || !v3_isfinite(s0->v) || !v3_isfinite(s0->w) ||
        !isfinite(s0->q.w + s0->q.x + s0->q.y + s0->q.z))
        return PD_ERR_NONFINITE;
    /* Planned in place, and only the fields before the theta series zeroed:
     * those are written when used, and the struct is mostly theirs. */
    pd_flight *F = f;
    memset(F, 0, offsetof(pd_flight, th));
    F->s0 = *s0;
    F->s0.q = quat_normalize(s0->q);
    F->g = g;
    for (int i = 0; i < 3; i++)
        F->J0[i] = b->inv_moment[i];
    pd_vec3 Lb = body_L(b, s0->w);
    F->lambda = v3_norm(Lb);
    F->wmax = wmax_bound(b->moment, s0->w, F->lambda * F->lambda);
    if (F->lambda == 0.0) {
        F->kind = PD_FLIGHT_STILL;
        return PD_OK;
    }
    pd_vec3 u = v3_scale(Lb, 1.0 / F->lambda);
    F->lhat = quat_rotate(F->s0.q, u);
    const double *I = b->moment, *J = b->inv_moment;

    /* Axial cases: equal moments (exact after the body's snapping), or u on a
     * principal axis (a steady spin, possibly about the unstable middle axis,
     * which an exact solution keeps). */
    int on_axis = principal_axis(u, PD_TOL_FLIGHT_AXIS_REL);
    if (I[0] == I[2] || on_axis >= 0 || I[0] == I[1] || I[1] == I[2]) {
        set_axial(F, I, J, u, on_axis);
        return PD_OK;
    }
    F->kind = PD_FLIGHT_BOUNDS; /* an asymmetric top: pd_flight_complete */
    return PD_OK;
}

pd_status pd_flight_complete(const pd_body *b, pd_flight *f)
{
    if (!b || !f)
        return PD_ERR_USAGE;
    if (f->kind != PD_FLIGHT_BOUNDS)
        return PD_OK;
    pd_vec3 u = v3_scale(body_L(b, f->s0.w), 1.0 / f->lambda);
    pd_status st = plan_elliptic(f, u, b->inv_moment);
    if (st != PD_OK) {
        /* Within PD_TOL_FLIGHT_NEAR_AXIS_REL of the separatrix's end, the
         * middle axis, the elliptic phase can overflow: a steady spin. */
        int near = principal_axis(u, PD_TOL_FLIGHT_NEAR_AXIS_REL);
        if (near < 0) {
            f->kind = PD_FLIGHT_BOUNDS; /* no flight: not to be evaluated */
            return st;
        }
        set_axial(f, b->moment, b->inv_moment, u, near);
    }
    return PD_OK;
}

pd_status pd_flight_eval(const pd_flight *f, double t, pd_state *out)
{
    if (t == 0.0) {
        /* The start itself: exact, and free (impact searches begin here). */
        *out = f->s0;
        return PD_OK;
    }
    pd_quat q = f->s0.q;
    pd_vec3 w = f->s0.w;
    if (f->kind == PD_FLIGHT_AXIAL) {
        /* omega_body(t) = rot(axis, -b t) omega_body(0): for equal moments J
         * commutes with that rotation (see the derivation in flight.h). A
         * spherical top or a steady spin (b = 0) turns about L alone: its
         * body rotation, the identity, is skipped (exactly what it gives). */
        q = quat_mul(turn(f->lhat, f->a * t), f->s0.q);
        if (f->b != 0.0) {
            pd_quat back = turn(f->axis, -f->b * t);
            q = quat_mul(q, quat_conj(back));
            w = quat_rotate(back, f->s0.w);
        }
    } else if (f->kind == PD_FLIGHT_ELLIPTIC) {
        double u[3], z[2] = {1.0, 0.0}, a; /* phi = arg z + 2a */
        if (f->theta) {
            double sn, cn, dn;
            pd_theta_eval(&f->th, t, &sn, &cn, &dn, z);
            u[0] = f->alpha[0] * cn;
            u[1] = f->alpha[1] * sn;
            u[2] = f->alpha[2] * dn;
            a = 0.5 * f->rate * t;
        } else {
            double P;
            pd_status st = elliptic_at(f, f->tau0 + f->Omega * t, u, &P);
            if (st != PD_OK)
                return st;
            a = 0.5 * f->lambda * (f->J[2] * t + (f->J[0] - f->J[2]) * (P - f->P0) / f->Omega);
        }
        double ac, as;
        pd_sincos(a, &as, &ac);
        q = times_e(f, quat_mul(f->Q0, chart_rotation(u, z[0], z[1], ac, as)));
        double wb[3];
        for (int i = 0; i < 3; i++)
            wb[f->perm[i]] = f->wsc[i] * u[i];
        w = v3(wb[0], wb[1], wb[2]);
    } else if (f->kind == PD_FLIGHT_BOUNDS) {
        return PD_ERR_USAGE; /* pd_flight_complete first */
    }
    const pd_state *s0 = &f->s0;
    out->x = v3(s0->x.x + s0->v.x * t, s0->x.y + s0->v.y * t,
                s0->x.z + s0->v.z * t - 0.5 * f->g * t * t);
    out->v = v3(s0->v.x, s0->v.y, s0->v.z - f->g * t);
    out->q = q;
    out->w = w;
    return PD_OK;
}

pd_status pd_flight_advance(const pd_body *b, pd_state *s, double g, double dt)
{
    pd_flight f;
    pd_status st = pd_flight_plan(b, s, g, &f);
    if (st != PD_OK)
        return st;
    return pd_flight_eval(&f, dt, s);
}
