/* impact.c: one frictional collision with the floor (see impact.h).
 *
 * Numerical decisions, each explained where it is made:
 *  - the problem is solved in units where |u0| = 1 and K's mean diagonal is
 *    1, so tolerances are relative and the law is homogeneous to round-off;
 *  - the integrated state is (px, py, W, pz), the velocity always recomputed
 *    as u0 + K p (impact_collision.h), and sliding integrated in a rescaled
 *    parameter in which zero slip is a rest point (impact_slide.c);
 *  - every phase in which p' is constant (no friction, stable sticking,
 *    sliding along the diverging ray or into the origin along an incoming
 *    one) is solved in closed form;
 *  - events are located by limiting each integrator step to the crossing
 *    predicted by a Newton step, by secant retries when a step overshoots,
 *    and by one step in the event's own variable once it is within a step,
 *    so the integrator never steps over the singularity of eq. 14. */
#include <math.h>
#include <stdlib.h>
#include "impact/impact_collision.h"
#include "impact/impact_slide.h"
#include "impact/impact_tol.h"

struct pd_impact_work {
    pd_ode *poisson;   /* dimension NSTATE_P: the impulse */
    pd_ode *energetic; /* NSTATE: and the normal work */
    double tol;        /* the integrators' local error per step, absolute and relative */
};

pd_impact_work *pd_impact_work_alloc(void)
{
    return pd_impact_work_alloc_tol(1.0);
}

pd_impact_work *pd_impact_work_alloc_tol(double tol_scale)
{
    pd_impact_work *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    double tol = tol_scale * PD_TOL_IMPACT_ODE_REL;
    w->tol = tol;
    w->poisson = pd_ode_alloc(NSTATE_P, tol, tol);
    w->energetic = pd_ode_alloc(NSTATE, tol, tol);
    if (!w->poisson || !w->energetic) {
        pd_impact_work_free(w);
        return NULL;
    }
    return w;
}

void pd_impact_work_free(pd_impact_work *w)
{
    if (!w)
        return;
    pd_ode_free(w->poisson);
    pd_ode_free(w->energetic);
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
    if (c->law == PD_IMPACT_POISSON)
        h = c->pz_end > c->y[PZ] ? c->pz_end - c->y[PZ] : 0.0;
    else if (c->W_end > c->y[PW]) /* uz >= 0 after compression */
        h = fmax(work_step(uz, q, c->W_end - c->y[PW]), 0.0);
    linear_advance(c, d, q, uz, h);
    c->done = 1;
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
    c.tol = w ? w->tol : 0.0;

    if (mu == 0.0) {
        /* No friction: p' = (0, 0, 1) throughout, closed form, no ODE. */
        linear_phase(&c, v3(0.0, 0.0, 1.0));
    } else {
        pd_status st = PD_OK;
        if (hypot(c.u0.x, c.u0.y) > PD_TOL_IMPACT_EVENT_REL)
            st = pd_impact_slide(&c, law == PD_IMPACT_POISSON ? w->poisson : w->energetic, &r.nsteps);
        if (st != PD_OK)
            return st;
        if (!c.done) {
            pd_vec3 d;
            r.stuck = !c.on_ray;
            if (!c.on_ray && stick_direction(CONST_M3(c.K), mu, &d)) {
                r.stick_stable = 1;
            } else {
                if (!coll_have_ray(&c))
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
