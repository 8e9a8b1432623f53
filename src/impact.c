/* impact.c: one frictional collision with the floor (see impact.h).
 *
 * Numerical decisions, each explained where it is made:
 *  - the problem is solved in units where |u0| = 1 and K's mean diagonal is
 *    1, so tolerances are relative and the law is homogeneous to round-off;
 *  - the integrated state is (px, py, W) with pz as the independent variable,
 *    and the velocity is always recomputed as u0 + K p, so u1 = u0 + K p holds
 *    exactly and the energy bookkeeping p.(u0 + u1)/2 matches the work;
 *  - every phase in which p' is constant (no friction, stable sticking,
 *    sliding along the diverging ray or into the origin along an incoming
 *    one) is solved in closed form;
 *  - events are located by limiting each integrator step to the crossing
 *    predicted by a Newton step, and by secant retries when a step overshoots,
 *    so the integrator never steps over the singularity of eq. 14. */
#include <math.h>
#include <stdlib.h>
#include "gsl_adapter.h"
#include "impact.h"
#include "impact_rays.h"
#include "posedrop/tolerances.h"
#include "mat3.h"
#include "vec3.h"

/* State of the sliding ODE: the impulse so far, and the normal work W. */
enum { PX, PY, PW, PZ, NSTATE };

struct pd_impact_work {
    pd_ode *ode;
};

pd_impact_work *pd_impact_work_alloc(void)
{
    pd_impact_work *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->ode = pd_ode_alloc(NSTATE, PD_TOL_IMPACT_ODE_REL, PD_TOL_IMPACT_ODE_REL);
    if (!w->ode) {
        free(w);
        return NULL;
    }
    return w;
}

void pd_impact_work_free(pd_impact_work *w)
{
    if (!w)
        return;
    pd_ode_free(w->ode);
    free(w);
}


void pd_impact_K(double inv_mass, const double Jinv[3][3], pd_vec3 r, double K[3][3])
{
    const double R[3][3] = {{0.0, -r.z, r.y}, {r.z, 0.0, -r.x}, {-r.y, r.x, 0.0}};
    double JR[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            JR[i][j] = Jinv[i][0] * R[0][j] + Jinv[i][1] * R[1][j] + Jinv[i][2] * R[2][j];
    double M[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            M[i][j] = (i == j ? inv_mass : 0.0) -
                      (R[i][0] * JR[0][j] + R[i][1] * JR[1][j] + R[i][2] * JR[2][j]);
    /* Exactly symmetric in exact arithmetic; averaging removes the round-off
     * asymmetry so that callers' symmetry checks see none. */
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            K[i][j] = 0.5 * (M[i][j] + M[j][i]);
}

/* --- the collision ------------------------------------------------------------ */

/* The normalised problem and the running state of one collision. */
typedef struct {
    double K[3][3];
    pd_vec3 u0;
    double mu, e;
    pd_impact_law law;
    double y[NSTATE]; /* p = (px, py, pz) and W so far */
    int have_ray;     /* sticking is unstable: the diverging ray (rtx, rty) exists */
    double rtx, rty;
    int on_ray;       /* sliding stopped on that ray */
    int scanned;      /* incoming rays looked for (a stiff approach) */
    pd_rays in;       /* ...and found */
    int compressed;
    double pz_c, W_c, pz_end, W_end;
    int done;
} collision;

static pd_vec3 coll_u(const collision *c, const double y[])
{
    return v3_add(c->u0, m3_vec(c->K, v3(y[PX], y[PY], y[PZ])));
}

/* Eq. 14 in a rescaled parameter tau with dpz/dtau = |u_t|: the state
 * (px, py, W, pz) obeys p' = (-mu u_x, -mu u_y, |u_t|), W' = u_z |u_t|.
 * Along a sliding trajectory this is eq. 14 with the step measure changed, so
 * it has the same solutions, but its right-hand side is Lipschitz: nothing is
 * divided by |u_t|, and the origin of the tangential plane becomes a rest
 * point approached exponentially in tau instead of a singularity reached at a
 * finite pz. In pz the flow near the origin turns the sliding direction at a
 * rate ~1/|u_t| (stiff: an explicit step must shrink with |u_t|, measured ~50
 * steps to come within 1e-9); in tau it turns at a bounded rate, and a
 * trajectory cannot step over the origin. */
static int slide_rhs(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const collision *c = user;
    pd_vec3 u = coll_u(c, y);
    double s = sqrt(u.x * u.x + u.y * u.y); /* |u| <~ 1 here: no overflow for hypot to guard */
    dydt[PX] = -c->mu * u.x;
    dydt[PY] = -c->mu * u.y;
    dydt[PW] = u.z * s;
    dydt[PZ] = s;
    return 0;
}

/* Marks maximum compression at the current state and sets the end target. */
static void coll_compress(collision *c)
{
    c->compressed = 1;
    c->pz_c = c->y[PZ];
    c->W_c = c->y[PW];
    c->pz_end = (1.0 + c->e) * c->pz_c;
    /* Stronge: restitution work -e^2 W_c, so the total normal work ends at
     * (1 - e^2) W_c (W_c <= 0). */
    c->W_end = (1.0 - c->e * c->e) * c->W_c;
    if (c->e == 0.0)
        c->done = 1;
}

/* Incoming rays are looked for only once a collision has taken this many
 * steps: a slip that is snapped onto one has approached it for that long. */
enum { RAY_SCAN_STEPS = 30 };

/* Advances by h along a constant impulse direction d = p'. */
static void linear_advance(collision *c, pd_vec3 d, double q, double uz, double h)
{
    c->y[PX] += h * d.x;
    c->y[PY] += h * d.y;
    c->y[PW] += h * uz + 0.5 * q * h * h;
    c->y[PZ] += h;
}

/* The rest of the collision with p' = d constant (no friction, stable
 * sticking, sliding along the diverging ray): u is linear in pz, W quadratic,
 * every event has a closed form. q = (K d)_z > 0 always: K_zz without
 * friction, the Schur complement K_zz - K_zt K_tt^-1 K_tz of an SPD matrix when
 * stuck, and on the diverging ray q = v'Kv + mu (t.a - mu t'Bt) > 0 with
 * v = (-mu t, 1), since t.a > mu t'Bt there. */
static void linear_phase(collision *c, pd_vec3 d)
{
    double q = m3_vec(CONST_M3(c->K), d).z;
    if (!(q > 0.0))
        return; /* cannot happen for SPD K (above); the caller's output check stops it */
    if (!c->compressed) {
        double uz = coll_u(c, c->y).z;
        double h = uz < 0.0 ? -uz / q : 0.0;
        linear_advance(c, d, q, uz, h);
        coll_compress(c);
    }
    if (c->done)
        return;
    double uz = coll_u(c, c->y).z, h = 0.0;
    if (c->law == PD_IMPACT_POISSON) {
        h = c->pz_end > c->y[PZ] ? c->pz_end - c->y[PZ] : 0.0;
    } else {
        /* W + uz h + q h^2 / 2 = W_end for the root h >= 0, in the form that
         * does not cancel (uz >= 0 after compression). */
        double dw = c->W_end - c->y[PW];
        if (dw > 0.0) {
            double den = uz + sqrt(uz * uz + 2.0 * q * dw);
            h = den > 0.0 ? 2.0 * dw / den : 0.0;
        }
    }
    linear_advance(c, d, q, uz, h);
    c->done = 1;
}

enum { EV_NONE, EV_COMPRESS, EV_END };

/* Sliding (eq. 14) until the collision ends or the tangential velocity
 * vanishes. Returns PD_OK with c->done set, or PD_OK with the state at
 * sticking (c->done clear), or a failure status. Integrates in tau (see
 * slide_rhs); events are functions of the state, located by limiting each
 * step to the Newton estimate of the crossing and by secant retries after an
 * overshoot. Sticking needs no location: the origin is a rest point in tau,
 * so a step may run past the moment |u_t| falls below the tolerance without
 * changing anything but tau. */
static pd_status slide(collision *c, pd_ode *ode, int *nsteps)
{
    const double tols = PD_TOL_IMPACT_EVENT_REL; /* |u0| = 1 */
    const double tolz = PD_TOL_IMPACT_EVENT_REL * fabs(c->u0.z);
    /* First trial step: u_t relaxes at rates ~mu K_tt ~ mu in these units,
     * and the normal velocity changes on a scale ~1; the controller adapts. */
    double tau = 0.0, h = 0.1 / (1.0 + c->mu);
    double cap = INFINITY; /* set by an overshoot: the next step ends there */
    int cap_event = EV_NONE;
    pd_ode_reset(ode);
    for (;;) {
        pd_vec3 u = coll_u(c, c->y);
        double s = sqrt(u.x * u.x + u.y * u.y);
        double tolw = PD_TOL_IMPACT_EVENT_REL * fabs(c->W_c);
        double tolp = PD_TOL_IMPACT_EVENT_REL * c->pz_end;
        if (!c->compressed && u.z >= -tolz)
            coll_compress(c);
        if (c->done)
            return PD_OK;
        if (c->compressed && c->law == PD_IMPACT_POISSON && c->y[PZ] >= c->pz_end - tolp) {
            /* Within the event tolerance of the end: close the gap along the
             * current impulse direction (error second order in the gap). */
            double gap = c->pz_end - c->y[PZ];
            if (s > 0.0) {
                c->y[PX] -= c->mu * u.x / s * gap;
                c->y[PY] -= c->mu * u.y / s * gap;
            }
            c->y[PW] += u.z * gap;
            c->y[PZ] = c->pz_end;
            c->done = 1;
            return PD_OK;
        }
        if (c->compressed && c->law == PD_IMPACT_ENERGETIC && c->y[PW] >= c->W_end - tolw) {
            c->done = 1;
            return PD_OK;
        }
        if (s <= tols)
            return PD_OK; /* stuck */
        /* Within the event tolerance of the diverging ray the trajectory is
         * on it for good: the ray attracts nearby directions, and along it p'
         * is constant (closed form). Integrating instead is stiff: when the
         * ray's outward speed is small the direction relaxes onto the ray
         * far faster than |u_t| grows (measured: > 1000 steps). */
        if (c->have_ray && u.x * c->rtx + u.y * c->rty > 0.0 &&
            fabs(c->rtx * u.y - c->rty * u.x) <= tols) {
            c->on_ray = 1;
            return PD_OK;
        }
        if (*nsteps >= RAY_SCAN_STEPS && !c->scanned) {
            pd_rays_incoming(CONST_M3(c->K), c->mu, &c->in);
            c->scanned = 1;
        }
        int in = -1;
        for (int k = 0; k < c->in.n && in < 0; k++)
            if (u.x * c->in.tx[k] + u.y * c->in.ty[k] > 0.0 &&
                fabs(c->in.tx[k] * u.y - c->in.ty[k] * u.x) <= tols)
                in = k;
        if (in >= 0) {
            /* On an incoming ray: p' = (-mu t, 1) until the slip reaches the
             * origin (at pz + s / |rate|), where it sticks, or the next normal
             * event, after which the loop's tests take over. */
            pd_vec3 d = v3(-c->mu * c->in.tx[in], -c->mu * c->in.ty[in], 1.0);
            double q = m3_vec(CONST_M3(c->K), d).z;
            double hs = s / -c->in.rate[in], he = INFINITY;
            if (!c->compressed && q > 0.0)
                he = -u.z / q;
            else if (c->compressed && c->law == PD_IMPACT_POISSON)
                he = c->pz_end - c->y[PZ];
            else if (c->compressed && q > 0.0) {
                double dw = c->W_end - c->y[PW];
                he = dw > 0.0 ? 2.0 * dw / (u.z + sqrt(u.z * u.z + 2.0 * q * dw)) : 0.0;
            }
            he = fmax(he, 0.0);
            linear_advance(c, d, q, u.z, fmin(hs, he));
            ++*nsteps;
            if (hs <= he)
                return PD_OK; /* stuck: what is left of the slip is the ray's offset, <= tols */
            pd_ode_reset(ode);
            continue;
        }
        if (*nsteps >= PD_IMPACT_MAX_STEPS)
            return PD_ERR_NO_CONVERGENCE;

        /* Newton predictions of the next events, from the slopes in tau:
         * d/dtau = |u_t| d/dpz, and in pz, u' = K (-mu t, 1). */
        double tx = u.x / s, ty = u.y / s;
        pd_vec3 du = m3_vec(CONST_M3(c->K), v3(-c->mu * tx, -c->mu * ty, 1.0));
        double hlim = INFINITY;
        int ev = EV_NONE;
        if (!c->compressed && du.z > 0.0 && -u.z / (s * du.z) < hlim) {
            hlim = -u.z / (s * du.z);
            ev = EV_COMPRESS;
        }
        if (c->compressed && c->law == PD_IMPACT_POISSON) {
            hlim = (c->pz_end - c->y[PZ]) / s;
            ev = EV_END;
        }
        if (c->compressed && c->law == PD_IMPACT_ENERGETIC) {
            /* W(tau) ~ W + A h + B h^2 / 2, A = u_z s,
             * B = d(u_z s)/dtau = s (s du_z + u_z ds/dpz). */
            double ds = tx * du.x + ty * du.y;
            double A = u.z * s, B = s * (s * du.z + u.z * ds);
            double dw = c->W_end - c->y[PW], disc = A * A + 2.0 * B * dw;
            double den = disc >= 0.0 ? A + sqrt(disc) : 0.0;
            if (den > 0.0) {
                hlim = 2.0 * dw / den;
                ev = EV_END;
            }
        }
        if (cap < hlim) {
            hlim = cap;
            ev = cap_event;
        }
        /* No event ahead: let the controller grow the step (it grows by at
         * most 5x, so 10 h never truncates it). */
        double t1 = ev == EV_NONE ? tau + 10.0 * h : tau + hlim;
        /* An event closer than round-off of tau is here: take it rather than
         * ask the integrator for a step it cannot represent. */
        if (!(t1 > tau)) {
            if (ev == EV_COMPRESS) {
                coll_compress(c);
                continue;
            }
            c->done = 1;
            return PD_OK;
        }

        double tau_a = tau, y_a[NSTATE];
        for (int i = 0; i < NSTATE; i++)
            y_a[i] = c->y[i];
        pd_status st = pd_ode_step(ode, slide_rhs, c, &tau, t1, &h, c->y);
        ++*nsteps;
        if (st != PD_OK)
            return st;
        cap = INFINITY;
        cap_event = EV_NONE;

        /* Overshoot: an event passed inside the step is bracketed and the
         * step retried to the secant estimate of its position. */
        pd_vec3 ub = coll_u(c, c->y);
        double frac = INFINITY;
        int fev = EV_NONE;
        if (!c->compressed && ub.z > tolz) {
            frac = -u.z / (ub.z - u.z);
            fev = EV_COMPRESS;
        }
        if (c->compressed && c->law == PD_IMPACT_POISSON && c->y[PZ] > c->pz_end + tolp) {
            frac = (c->pz_end - y_a[PZ]) / (c->y[PZ] - y_a[PZ]);
            fev = EV_END;
        }
        if (c->compressed && c->law == PD_IMPACT_ENERGETIC && c->y[PW] > c->W_end + tolw) {
            frac = (c->W_end - y_a[PW]) / (c->y[PW] - y_a[PW]);
            fev = EV_END;
        }
        if (fev != EV_NONE) {
            cap = frac * (tau - tau_a);
            cap_event = fev;
            tau = tau_a;
            for (int i = 0; i < NSTATE; i++)
                c->y[i] = y_a[i];
            pd_ode_reset(ode);
        }
    }
}

/* Eq. 15: with u_t = 0, p' = (alpha, beta, 1) keeps u_t' = 0 when
 * K_tt (alpha, beta) = -K_tz. Returns 1 if friction can hold it
 * (alpha^2 + beta^2 <= mu^2). A 2x2 solve on K_tt, not a row of K^-1, so an
 * ill-conditioned normal direction does not pollute it. */
static int stick_direction(const double K[3][3], double mu, pd_vec3 *d)
{
    double det = K[0][0] * K[1][1] - K[0][1] * K[1][0];
    double al = (-K[0][2] * K[1][1] + K[1][2] * K[0][1]) / det;
    double be = (-K[1][2] * K[0][0] + K[0][2] * K[1][0]) / det;
    *d = v3(al, be, 1.0);
    return al * al + be * be <= mu * mu;
}

static int is_spd(const double K[3][3])
{
    double d1 = K[0][0];
    double d2 = K[0][0] * K[1][1] - K[0][1] * K[1][0];
    double d3 = K[0][0] * (K[1][1] * K[2][2] - K[1][2] * K[2][1]) -
                K[0][1] * (K[1][0] * K[2][2] - K[1][2] * K[2][0]) +
                K[0][2] * (K[1][0] * K[2][1] - K[1][1] * K[2][0]);
    return d1 > 0.0 && d2 > 0.0 && d3 > 0.0;
}

pd_status pd_impact_solve(pd_impact_work *w, const double K[3][3], pd_vec3 u0, double mu, double e,
                          pd_impact_law law, pd_impact_result *out)
{
    if (!out || !K)
        return PD_ERR_USAGE;
    double kmax = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            if (!isfinite(K[i][j]))
                return PD_ERR_NONFINITE;
            kmax = fmax(kmax, fabs(K[i][j]));
        }
    if (!v3_isfinite(u0) || !isfinite(mu) || !isfinite(e))
        return PD_ERR_NONFINITE;
    if (!(mu >= 0.0) || !(e >= 0.0 && e <= 1.0) || (mu > 0.0 && !w))
        return PD_ERR_USAGE;
    if (law != PD_IMPACT_POISSON && law != PD_IMPACT_ENERGETIC)
        return PD_ERR_USAGE;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < i; j++)
            if (fabs(K[i][j] - K[j][i]) > PD_TOL_IMPACT_K_SYM_REL * kmax)
                return PD_ERR_USAGE;
    if (!is_spd(K))
        return PD_ERR_USAGE;

    pd_impact_result r = {0};
    r.u1 = u0;
    if (!(u0.z < 0.0)) {
        *out = r; /* not approaching: no impulse */
        return PD_OK;
    }

    /* Units: |u0| = 1, mean diagonal of K = 1. The solution for (K, u0) is
     * (|u0| / k) times that for (K / k, u0 / |u0|): the law is homogeneous. */
    double uscale = v3_norm(u0);
    double kscale = (K[0][0] + K[1][1] + K[2][2]) / 3.0;
    collision c = {0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            c.K[i][j] = 0.5 * (K[i][j] + K[j][i]) / kscale;
    c.u0 = v3_scale(u0, 1.0 / uscale);
    c.mu = mu;
    c.e = e;
    c.law = law;

    if (mu == 0.0) {
        /* No friction: p' = (0, 0, 1) throughout, closed form, no ODE. */
        linear_phase(&c, v3(0.0, 0.0, 1.0));
    } else {
        pd_status st = PD_OK;
        c.have_ray = pd_ray_diverging(CONST_M3(c.K), mu, &c.rtx, &c.rty);
        if (hypot(c.u0.x, c.u0.y) > PD_TOL_IMPACT_EVENT_REL)
            st = slide(&c, w->ode, &r.nsteps);
        if (st != PD_OK)
            return st;
        if (!c.done) {
            pd_vec3 d;
            r.stuck = !c.on_ray;
            if (!c.on_ray && stick_direction(CONST_M3(c.K), mu, &d)) {
                r.stick_stable = 1;
            } else {
                if (!c.have_ray)
                    return PD_ERR_INTERNAL; /* unstable sticking always has its ray */
                r.resumed = 1;
                r.theta_e = atan2(c.rty, c.rtx);
                d = v3(-mu * c.rtx, -mu * c.rty, 1.0);
            }
            linear_phase(&c, d);
        }
    }

    double pscale = uscale / kscale;
    r.p = v3_scale(v3(c.y[PX], c.y[PY], c.y[PZ]), pscale);
    r.u1 = v3_add(u0, m3_vec(K, r.p));
    r.pz_c = c.pz_c * pscale;
    r.dke = 0.5 * v3_dot(r.p, v3_add(u0, r.u1));
    r.energy_gain = r.dke > PD_TOL_IMPACT_ENERGY_REL * v3_norm(r.p) * uscale;
    if (!v3_isfinite(r.p) || !v3_isfinite(r.u1) || !isfinite(r.dke) || !isfinite(r.pz_c))
        return PD_ERR_INTERNAL;
    *out = r;
    return PD_OK;
}
