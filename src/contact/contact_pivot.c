/* contact_pivot.c: two sticking contacts as a rotation about the edge
 * through them (see contact_pivot.h).
 *
 * Both contacts at rest fix the line through them, so the part can only
 * turn about it: one angle a, with I_e a'' = gravity's torque about the
 * edge (the contact forces act on the axis and have none), a pendulum. The
 * state and the forces are explicit functions of a, a' and a'', so the
 * phase has two unknowns instead of thirteen and solves no force system
 * (and the pendulum is solved in closed form, pd_pivot_run, below): the
 * forces follow from the motion, the total force from the
 * centre's acceleration and the moment from Euler's equations, split
 * between the contacts with no squeeze along the edge, as the phase's
 * least-norm solve splits them (phase_forces.c). Sticking contacts do no
 * work, so the energy is constant. */
#include <math.h>
#include "contact/contact_pivot.h"
#include "contact/contact_tol.h"
#include "base/gsl_adapter.h"
#include "base/illinois.h"
#include "base/quat.h"
#include "base/vec3.h"

int pd_pivot_init(pd_pivot *pv, const pd_phase *p, const pd_state *s0)
{
    if (p->nc != 2 || p->mode[0] != PD_PHASE_STICK || p->mode[1] != PD_PHASE_STICK)
        return 0;
    const pd_body *b = p->b;
    pd_vec3 r0 = quat_rotate(s0->q, p->r[0]), r1 = quat_rotate(s0->q, p->r[1]);
    pd_vec3 edge = v3_sub(r1, r0);
    double len = v3_norm(edge);
    if (!(len > 0.0))
        return 0;
    pv->p = p;
    pv->len = len;
    pv->p0 = v3_add(s0->x, r0);
    pv->e = v3_scale(edge, 1.0 / len);
    pv->eb = v3_scale(v3_sub(p->r[1], p->r[0]), 1.0 / len);
    pd_vec3 u = v3_neg(r0);
    pv->u_par = v3_scale(pv->e, v3_dot(u, pv->e));
    pv->u_perp = v3_sub(u, pv->u_par);
    pv->e_u = v3_cross(pv->e, pv->u_perp);
    pv->q0 = s0->q;
    pv->Ieb = v3(b->moment[0] * pv->eb.x, b->moment[1] * pv->eb.y, b->moment[2] * pv->eb.z);
    pv->gyro = v3_cross(pv->eb, pv->Ieb);
    pv->Ie = v3_dot(pv->eb, pv->Ieb) + b->mass * v3_dot(pv->u_perp, pv->u_perp);
    /* The centre's height over p0 is u_par.z + cos a u_perp.z + sin a e_u.z:
     * its torque is minus m g times the height's derivative. */
    double mg = b->mass * p->g;
    pv->k_sin = mg * pv->u_perp.z / pv->Ie;
    pv->k_cos = -mg * pv->e_u.z / pv->Ie;
    return 1;
}

double pd_pivot_rate_of(const pd_pivot *pv, const pd_state *s)
{
    /* The angular momentum about the axis over the moment about it: the
     * body's own (I w along eb, body frame) and the centre's orbit
     * (u x m v, u the arm from the axis). */
    pd_vec3 u = v3_add(pv->u_par, pv->u_perp);
    double orbit = pv->p->b->mass * v3_dot(pv->e, v3_cross(u, s->v));
    return (v3_dot(pv->Ieb, s->w) + orbit) / pv->Ie;
}

/* cos a and sin a from the half angle's, which the orientation needs too. */
static void turn(double a, double *ch, double *sh, double *c, double *s)
{
    *ch = cos(0.5 * a), *sh = sin(0.5 * a);
    *c = 1.0 - 2.0 * *sh * *sh;
    *s = 2.0 * *sh * *ch;
}

double pd_pivot_accel(const pd_pivot *pv, double a)
{
    double ch, sh, c, s;
    turn(a, &ch, &sh, &c, &s);
    return pv->k_sin * s + pv->k_cos * c;
}

double pd_pivot_state(const pd_pivot *pv, double a, double w, pd_state *st, pd_phase_forces *F)
{
    const pd_phase *p = pv->p;
    const pd_body *b = p->b;
    double ch, sh, c, s;
    turn(a, &ch, &sh, &c, &s);
    double alpha = pv->k_sin * s + pv->k_cos * c;
    pd_vec3 arm = v3_add(v3_scale(pv->u_perp, c), v3_scale(pv->e_u, s)); /* across the axis */
    pd_vec3 d = v3_add(pv->u_par, arm);
    pd_vec3 across = v3_cross(pv->e, arm);                                /* e x arm */
    st->x = v3_add(pv->p0, d);
    st->q = quat_normalize(quat_mul(quat(ch, sh * pv->e.x, sh * pv->e.y, sh * pv->e.z), pv->q0));
    st->v = v3_scale(across, w);
    st->w = v3_scale(pv->eb, w);
    pd_vec3 acc = v3_sub(v3_scale(across, alpha), v3_scale(arm, w * w));
    /* Contact forces f0 + f1 = m (acc + g z) and, about the centre,
     * r0 x f0 + r1 x f1 = R (I wdot + w x I w): f1 eliminated, the edge D
     * crossed with f0 is given, which fixes f0 across the edge, and no
     * squeeze shares the force along it equally. */
    pd_vec3 sum = v3_scale(v3(acc.x, acc.y, acc.z + p->g), b->mass);
    pd_vec3 torque = quat_rotate(st->q, v3_add(v3_scale(pv->Ieb, alpha), v3_scale(pv->gyro, w * w)));
    pd_vec3 r1 = v3_sub(v3_scale(pv->e, pv->len), d);
    pd_vec3 cvec = v3_sub(torque, v3_cross(r1, sum));
    pd_vec3 f[2];
    f[0] = v3_add(v3_scale(v3_cross(pv->e, cvec), 1.0 / pv->len),
                  v3_scale(pv->e, 0.5 * v3_dot(sum, pv->e)));
    f[1] = v3_sub(sum, f[0]);
    F->acc = acc;
    F->wdot = v3_scale(pv->eb, alpha);
    for (int j = 0; j < 2; j++) {
        F->fn[j] = f[j].z;
        F->cone[j] = p->mu * f[j].z - sqrt(f[j].x * f[j].x + f[j].y * f[j].y);
        F->slip[j] = 0.0; /* on the axis */
    }
    return alpha;
}

/* --- The pivot run in closed form ---------------------------------------
 *
 * The energy gives the rate at every angle. In the part's units (rates per
 * sqrt(L/g)), w(a)^2 = w0^2 + 2 k_sin (1 - cos a) + 2 k_cos sin a
 * = A - 2 rho cos(a + psi), A = w0^2 + 2 k_sin, rho cos psi = k_sin,
 * rho sin psi = k_cos. With th = (a + psi + pi) / 2 that is
 * (A + 2 rho) (1 - m sin^2 th), m = 4 rho / (A + 2 rho), so the time
 * da / |w| is 2 / sqrt(A + 2 rho) times Legendre's dF(th | m): a
 * pendulum's. The part's heights above the floor turn as A + B cos a +
 * C sin a (a rotation about a fixed axis), and the forces are functions of
 * the angle alone (they take the rate as w^2), so every event is an angle,
 * found without the time, which follows from F. */
typedef struct {
    const pd_pivot *pv;
    double T;          /* sqrt(L/g), s */
    double w0sq, ks, kc; /* w0^2, k_sin, k_cos in the part's units */
    double psi, m, scale; /* psi, m, 2 / sqrt(A + 2 rho) as below */
    double th_ref;     /* th at a = 0 rounded to a multiple of pi */
    double K;          /* F(pi/2 | m) where m < 1, for angles a half turn apart */
} pend;

static double pend_w2(const pend *pe, double a)
{
    return pe->w0sq + 2.0 * pe->ks * (1.0 - cos(a)) + 2.0 * pe->kc * sin(a);
}

/* F(th | m) from th_ref, for an angle a of the motion; NAN where it cannot
 * be had (an evaluation out of range). Within a motion that turns back
 * (m > 1), th stays within pi/2 of th_ref, where F needs no K. */
static double pend_F(const pend *pe, double a)
{
    double th = 0.5 * (a + pe->psi + M_PI) - pe->th_ref;
    double n = nearbyint(th / M_PI), r = th - n * M_PI, s = sin(r), c = cos(r), rf;
    if (pd_ellint_RF(c * c, fmax(0.0, 1.0 - pe->m * s * s), 1.0, &rf) != PD_OK)
        return NAN;
    if (n != 0.0) {
        if (!(pe->K > 0.0))
            return NAN;
        return s * rf + 2.0 * n * pe->K;
    }
    return s * rf;
}

static int pend_init(pend *pe, const pd_pivot *pv, double w0)
{
    double T = sqrt(pv->p->L / pv->p->g), T2 = T * T;
    pe->pv = pv, pe->T = T;
    pe->w0sq = w0 * T * w0 * T, pe->ks = pv->k_sin * T2, pe->kc = pv->k_cos * T2;
    double rho = hypot(pe->ks, pe->kc), top = pe->w0sq + 2.0 * pe->ks + 2.0 * rho;
    if (!(rho > 0.0) || !(top > 0.0))
        return 0;
    pe->psi = atan2(pe->kc, pe->ks);
    pe->m = 4.0 * rho / top;
    pe->scale = 2.0 / sqrt(top);
    pe->th_ref = M_PI * nearbyint((0.5 * (pe->psi + M_PI)) / M_PI);
    pe->K = 0.0;
    if (pe->m < 1.0 && pd_ellint_RF(0.0, 1.0 - pe->m, 1.0, &pe->K) != PD_OK)
        return 0;
    return 1;
}

/* The first t > 0 where P + Q cos(sigma t) + S sin(sigma t) reaches 0,
 * given positive at t = 0; INFINITY if never. */
static double first_zero(double P, double Q, double S, double sigma)
{
    double R = hypot(Q, S);
    if (!(R > 0.0) || fabs(P) > R)
        return INFINITY;
    double beta = atan2(sigma * S, Q), gam = acos(-P / R), best = INFINITY;
    for (int k = -1; k <= 1; k += 2) {
        double t = fmod(beta + k * gam, 2.0 * M_PI);
        if (t <= 0.0)
            t += 2.0 * M_PI;
        best = fmin(best, t);
    }
    return best;
}

/* The least of the contacts' normal forces and cone margins at angle a
 * (per unit weight): where it reaches 0 a contact lifts or slips. */
static double pend_force_margin(const pend *pe, double a)
{
    const pd_phase *p = pe->pv->p;
    pd_state s;
    pd_phase_forces F;
    double w2 = fmax(0.0, pend_w2(pe, a));
    pd_pivot_state(pe->pv, a, sqrt(w2) / pe->T, &s, &F);
    double mg = p->b->mass * p->g;
    return fmin(fmin(F.fn[0], F.fn[1]), fmin(F.cone[0], F.cone[1])) / mg;
}

/* The first landing along sigma from angle 0: the least first_zero of the
 * heights above the floor of the contacts' neighbours (contact_phase.c's
 * margins); 0 where one is not above it at 0. */
static double pend_landing(const pend *pe, double sigma)
{
    const pd_pivot *pv = pe->pv;
    const pd_phase *p = pv->p;
    const pd_body *b = p->b;
    pd_vec3 r1 = v3_scale(pv->e, pv->len); /* contact 1 from contact 0, world */
    double zf = r1.z < 0.0 ? r1.z : 0.0, best = INFINITY;
    for (int i = 0; i < 2; i++)
        for (int k = b->adj_start[p->v[i]]; k < b->adj_start[p->v[i] + 1]; k++) {
            int w = b->adj[k];
            if (w == p->v[0] || w == p->v[1])
                continue;
            pd_vec3 d = quat_rotate(pv->q0, v3_sub(b->verts[w], p->r[0]));
            pd_vec3 par = v3_scale(pv->e, v3_dot(d, pv->e)), perp = v3_sub(d, par);
            double P = par.z - zf, Q = perp.z, S = v3_cross(pv->e, perp).z;
            if (!(P + Q > 0.0))
                return 0.0;
            best = fmin(best, first_zero(P, Q, S, sigma));
        }
    return best;
}

/* The first angle t in (0, span] along sigma where the force margin
 * reaches 0 (INFINITY if none): sampled every PD_PIVOT_CELL rad, the cell
 * where it does narrowed by regula falsi (Illinois) to round-off. 0 where it
 * is not positive at 0. */
static double pend_force_event(const pend *pe, double sigma, double span)
{
    double lo = 0.0, flo = pend_force_margin(pe, 0.0);
    if (!(flo > 0.0))
        return 0.0;
    int cells = (int)ceil(span / PD_PIVOT_CELL);
    for (int i = 1; i <= cells; i++) {
        double hi = i == cells ? span : span * i / cells, fhi = pend_force_margin(pe, sigma * hi);
        if (fhi > 0.0) {
            lo = hi, flo = fhi;
            continue;
        }
        int side = 0;
        for (int it = 0; it < 100 && hi - lo > PD_TOL_PIVOT_ANGLE; it++) {
            double x = lo + flo / (flo - fhi) * (hi - lo);
            if (!(x > lo && x < hi))
                x = 0.5 * (lo + hi);
            double f = pend_force_margin(pe, sigma * x);
            if (f > 0.0)
                lo = x, flo = f;
            else
                hi = x, fhi = f;
            pd_illinois_moved(f > 0.0, &side, &flo, &fhi);
        }
        return lo;
    }
    return INFINITY;
}

/* The angle and rate (per sqrt(L/g)) at u = F(th | m) along the motion,
 * Jacobi's amplitude: past a turn (m > 1, by the reciprocal modulus) as
 * well as before it, u moving with time as sigma / scale. 1 if had. */
static int pend_at(const pend *pe, double sigma, double u, double *a, double *w)
{
    double th, dth, sn, cn, dn;
    if (pe->m < 1.0) {
        double n = nearbyint(u / (2.0 * pe->K)), r = u - 2.0 * n * pe->K;
        if (pd_elljac(r, pe->m, &sn, &cn, &dn) != PD_OK)
            return 0;
        th = atan2(sn, cn) + n * M_PI, dth = dn;
    } else {
        double k = sqrt(pe->m);
        if (pd_elljac(k * u, 1.0 / pe->m, &sn, &cn, &dn) != PD_OK)
            return 0;
        th = atan2(sn / k, dn), dth = cn;
    }
    *a = 2.0 * (th + pe->th_ref) - pe->psi - M_PI;
    *w = 2.0 * sigma * dth / pe->scale;
    return isfinite(*a) && isfinite(*w);
}

int pd_pivot_run(const pd_pivot *pv, double w0, double t_max, double lead, double *a, double *w,
                 double *t)
{
    pend pe;
    if (!(w0 != 0.0) || !pend_init(&pe, pv, w0))
        return 0;
    double sigma = w0 > 0.0 ? 1.0 : -1.0, u0 = pend_F(&pe, 0.0);
    /* Along sigma: to the first landing or the turning point (the rate's
     * square reaching 0), whichever comes first, and a force event short
     * of it. */
    double land = pend_landing(&pe, sigma);
    double turn = first_zero(pe.w0sq + 2.0 * pe.ks, -2.0 * pe.ks, 2.0 * pe.kc, sigma);
    double end = fmin(land, turn);
    if (!isfinite(end) || !isfinite(u0))
        return 0;
    double force = pend_force_event(&pe, sigma, end), u_event;
    if (force <= end || land <= turn) {
        u_event = pend_F(&pe, sigma * fmin(force, land));
    } else {
        /* It turns back (the centre short of passing over the edge), u
         * going on past the turn's, K(1/m) / sqrt(m): back through 0, which
         * the margins have been checked to, to the first event on the other
         * side, where F is the mirror image of its value there. A second
         * turn (a pendulum hanging below its edge, which no convex part's
         * pivot is) is left to the integrator. */
        double land2 = pend_landing(&pe, -sigma);
        double turn2 = first_zero(pe.w0sq + 2.0 * pe.ks, -2.0 * pe.ks, 2.0 * pe.kc, -sigma), K1;
        if (!(land2 < turn2) || !(pe.m > 1.0) ||
            pd_ellint_RF(0.0, 1.0 - 1.0 / pe.m, 1.0, &K1) != PD_OK)
            return 0;
        double u_turn = sigma * K1 / sqrt(pe.m);
        u_event = 2.0 * u_turn - pend_F(&pe, -sigma * fmin(land2, pend_force_event(&pe, -sigma, land2)));
    }
    /* Hand over lead before the event, or at t_max. */
    double tau = sigma * (u_event - u0) * pe.scale - lead / pe.T;
    if (!isfinite(tau))
        return 0;
    tau = fmin(tau, t_max / pe.T);
    if (!(tau > 0.0)) {
        *a = 0.0, *w = w0, *t = 0.0;
        return 1;
    }
    double wT;
    if (!pend_at(&pe, sigma, u0 + sigma * tau / pe.scale, a, &wT))
        return 0;
    *w = wT / pe.T;
    *t = tau * pe.T;
    return 1;
}
