/* impact_slide.c: a collision's sliding phase, eq. 14 integrated with GSL's
 * rk8pd (see impact_internal.h).
 *
 * Eq. 14 gives p and W as functions of pz. The integrator runs in a
 * parameter sigma of our choosing, with dpz/dsigma = g > 0 along the
 * trajectory: a change of step measure, so every choice has the same
 * solutions. The state is (px, py, W, pz) in every form. */
#include <math.h>
#include "impact_internal.h"
#include "posedrop/tolerances.h"

enum {
    FORM_TAU, /* g = |u_t|: every ordinary step (rhs_tau) */
    FORM_PZ,  /* g = 1: sigma = pz, one step onto Poisson's end */
    FORM_UZ,  /* g = 1 / (du_z/dpz): sigma = u_z, one step onto maximum compression */
    FORM_W    /* g = 1 / u_z: sigma = W, one step onto the energetic end */
};

/* Eq. 14 in tau, dpz/dtau = |u_t|: p' = (-mu u_x, -mu u_y, |u_t|),
 * W' = u_z |u_t|. Its right-hand side is Lipschitz: nothing is divided by
 * |u_t|, and the origin of the tangential plane becomes a rest point
 * approached exponentially in tau instead of a singularity reached at a
 * finite pz. In pz the flow near the origin turns the sliding direction at a
 * rate ~1/|u_t| (stiff: an explicit step must shrink with |u_t|, measured ~50
 * steps to come within 1e-9); in tau it turns at a bounded rate, and a
 * trajectory cannot step over the origin. Integrating in pz where the slip
 * is large did not pay: rk8pd's steps there are as long in pz as in tau
 * (the turning of the direction sets both), and were refused more often. */
static int rhs_tau(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const collision *c = user;
    pd_vec3 u = coll_u(c, y);
    double s = sqrt(u.x * u.x + u.y * u.y); /* |u| <~ 1 here: no overflow for hypot to guard */
    dydt[PX] = -c->mu * u.x;
    dydt[PY] = -c->mu * u.y;
    dydt[PZ] = s;
    if (c->law == PD_IMPACT_ENERGETIC)
        dydt[PW] = u.z * s;
    return 0;
}

/* Eq. 14 in pz: p' = (-mu t, 1), W' = u_z. */
static int rhs_pz(double pz, const double y[], double dydt[], void *user)
{
    (void)pz;
    const collision *c = user;
    pd_vec3 u = coll_u(c, y);
    double m = c->mu / sqrt(u.x * u.x + u.y * u.y);
    dydt[PX] = -m * u.x;
    dydt[PY] = -m * u.y;
    dydt[PZ] = 1.0;
    if (c->law == PD_IMPACT_ENERGETIC)
        dydt[PW] = u.z;
    return 0;
}

/* The same divided by q = du_z/dpz = K_zz - mu K_zt.t, which the caller
 * keeps positive for every direction. */
static int rhs_uz(double uz, const double y[], double dydt[], void *user)
{
    (void)uz;
    const collision *c = user;
    pd_vec3 u = coll_u(c, y);
    double s = sqrt(u.x * u.x + u.y * u.y);
    double q = c->K[2][2] - c->mu * (c->K[2][0] * u.x + c->K[2][1] * u.y) / s;
    double m = c->mu / (s * q);
    dydt[PX] = -m * u.x;
    dydt[PY] = -m * u.y;
    dydt[PZ] = 1.0 / q;
    if (c->law == PD_IMPACT_ENERGETIC)
        dydt[PW] = u.z / q;
    return 0;
}

/* The same divided by u_z, which the caller keeps positive. */
static int rhs_w(double w, const double y[], double dydt[], void *user)
{
    (void)w;
    const collision *c = user;
    pd_vec3 u = coll_u(c, y);
    double m = c->mu / (sqrt(u.x * u.x + u.y * u.y) * u.z);
    dydt[PX] = -m * u.x;
    dydt[PY] = -m * u.y;
    dydt[PZ] = 1.0 / u.z;
    dydt[PW] = 1.0; /* the energetic law's only */
    return 0;
}

static const pd_ode_fn form_rhs[] = {rhs_tau, rhs_pz, rhs_uz, rhs_w};

/* First trial step in tau, times (1 + mu): u_t relaxes at rates ~mu K_tt
 * ~mu in these units, the normal velocity on a scale ~1, and rk8pd's first
 * accepted steps at 1e-11 are about this long (0.1 spent a step or two
 * growing to it, 1 as many being refused). */
#define TAU_FIRST_STEP 0.3

/* Incoming rays are looked for once the slip falls below this (units of
 * |u0|): a trajectory is within the event tolerance of one only near the
 * origin or if it started on it exactly, and 2k instructions are saved
 * where it never comes near. Measured: the same steps at 0.1 as at any
 * slip; at 0.03 an energetic cube's collisions took 0.6% more. */
#define RAYS_SLIP 0.1

enum { EV_NONE, EV_COMPRESS, EV_END };

/* The event ahead and its Newton estimate in tau, *h (INFINITY if none):
 * in pz, u' = K (-mu t, 1) = du, and dpz = |u_t| dtau. */
static int next_event(const collision *c, pd_vec3 u, double s, pd_vec3 du, double *h)
{
    *h = INFINITY;
    if (!c->compressed) {
        if (!(du.z > 0.0))
            return EV_NONE;
        *h = -u.z / (du.z * s);
        return EV_COMPRESS;
    }
    if (c->law == PD_IMPACT_POISSON) {
        *h = (c->pz_end - c->y[PZ]) / s;
        return EV_END;
    }
    /* W(tau) ~ W + A h + B h^2 / 2, A = u_z s,
     * B = d(u_z s)/dtau = s (s du_z + u_z ds/dpz), ds/dpz = t.du. */
    double ds = (u.x * du.x + u.y * du.y) / s;
    double hw = work_step(u.z * s, s * (s * du.z + u.z * ds), c->W_end - c->y[PW]);
    if (!(hw >= 0.0))
        return EV_NONE;
    *h = hw;
    return EV_END;
}

pd_status pd_impact_slide(collision *c, pd_ode *ode, int *nsteps)
{
    const double tols = PD_TOL_IMPACT_EVENT_REL; /* |u0| = 1 */
    const double tolz = PD_TOL_IMPACT_EVENT_REL * fabs(c->u0.z);
    /* q = du_z/dpz = K_zz - mu K_zt.t for the least favourable direction t. */
    const double qmin = c->K[2][2] - c->mu * hypot(c->K[2][0], c->K[2][1]);
    double tau = 0.0, h = TAU_FIRST_STEP / (1.0 + c->mu);
    double cap = INFINITY; /* set by an overshoot: the next step ends there */
    int cap_event = EV_NONE;
    int fresh = 1;  /* the integrator's last derivative is not the state's: restart it */
    int henon = 1;  /* cleared if a step onto an event ever fails */
    c->in.n = -1; /* not looked for yet */
    for (;;) {
        pd_vec3 u = coll_u(c, c->y);
        double s = sqrt(u.x * u.x + u.y * u.y);
        double tolw = PD_TOL_IMPACT_EVENT_REL * fabs(c->W_c);
        double tolp = PD_TOL_IMPACT_EVENT_REL * c->pz_end;
        if (!c->compressed && u.z >= -tolz)
            coll_compress(c);
        if (c->done)
            return PD_OK;
        /* The impulse's direction now, for closing the gap to an end. */
        pd_vec3 d = s > 0.0 ? v3(-c->mu * u.x / s, -c->mu * u.y / s, 1.0) : v3(0.0, 0.0, 1.0);
        if (c->compressed && c->law == PD_IMPACT_POISSON && c->y[PZ] >= c->pz_end - tolp) {
            /* Within the event tolerance of the end: close the gap along the
             * current impulse direction (error second order in the gap). */
            linear_advance(c, d, 0.0, u.z, c->pz_end - c->y[PZ]);
            c->y[PZ] = c->pz_end;
            c->done = 1;
            return PD_OK;
        }
        if (c->compressed && c->law == PD_IMPACT_ENERGETIC && c->y[PW] >= c->W_end - tolw) {
            /* The same for the energetic end, W + u_z h + q h^2 / 2 = W_end:
             * left open, the tolerance on W would stay in pz as an error of
             * tolw / u_z, large when e is small. */
            double q = m3_vec(CONST_M3(c->K), d).z, gap = work_step(u.z, q, c->W_end - c->y[PW]);
            if (isfinite(gap)) {
                linear_advance(c, d, q, u.z, gap);
                c->y[PW] = c->W_end;
            }
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
        /* The same on an incoming ray, approached as stiffly (measured: 1 in
         * 1e5 random impacts exceeded PD_IMPACT_MAX_STEPS). Looked for once
         * the slip is small (RAYS_SLIP). */
        if (c->in.n < 0 && s < RAYS_SLIP)
            pd_rays_incoming(CONST_M3(c->K), c->mu, &c->in);
        int in = -1;
        for (int k = 0; k < c->in.n && in < 0; k++)
            if (u.x * c->in.tx[k] + u.y * c->in.ty[k] > 0.0 &&
                fabs(c->in.tx[k] * u.y - c->in.ty[k] * u.x) <= tols)
                in = k;
        if (in >= 0) {
            /* p' = (-mu t, 1) until the slip reaches the origin (at
             * pz + s / |rate|), where it sticks, or the next normal event,
             * after which the loop's tests take over. */
            pd_vec3 dr = v3(-c->mu * c->in.tx[in], -c->mu * c->in.ty[in], 1.0);
            double q = m3_vec(CONST_M3(c->K), dr).z;
            double hs = s / -c->in.rate[in], he = INFINITY;
            if (!c->compressed && q > 0.0)
                he = -u.z / q;
            else if (c->compressed && c->law == PD_IMPACT_POISSON)
                he = c->pz_end - c->y[PZ];
            else if (c->compressed && q > 0.0)
                he = c->W_end > c->y[PW] ? work_step(u.z, q, c->W_end - c->y[PW]) : 0.0;
            he = fmax(he, 0.0);
            linear_advance(c, dr, q, u.z, fmin(hs, he));
            ++*nsteps;
            if (hs <= he)
                return PD_OK; /* stuck: what is left of the slip is the ray's offset, <= tols */
            fresh = 1;
            continue;
        }
        if (*nsteps >= PD_IMPACT_MAX_STEPS)
            return PD_ERR_NO_CONVERGENCE;

        pd_vec3 du = m3_vec(CONST_M3(c->K), d);
        double hlim;
        int ev = next_event(c, u, s, du, &hlim);

        /* Henon's trick: an event the next step would reach is landed on by
         * one step in its own variable, which ends exactly there, instead of
         * by Newton steps that each leave a residual (two or three steps an
         * event). Only where that variable is a smooth parameter all along
         * the step: the slip stays away from zero (it cannot fall below half
         * by the Newton estimate), and the variable's rate away from zero:
         * q > 1/4 of its value here for every direction, u_z > 4 times its
         * growth over the step. */
        if (henon && ev != EV_NONE && isinf(cap) && hlim <= h &&
            (u.x * du.x + u.y * du.y) * hlim >= -0.5 * s) {
            int f = -1;
            double e0 = 0.0, e1 = 0.0, rate = 0.0; /* sigma from e0 to e1, dsigma/dpz = rate */
            if (ev == EV_COMPRESS && qmin > 0.25 * du.z)
                f = FORM_UZ, e0 = u.z, e1 = 0.0, rate = du.z;
            else if (ev == EV_END && c->law == PD_IMPACT_POISSON)
                f = FORM_PZ, e0 = c->y[PZ], e1 = c->pz_end, rate = 1.0;
            else if (ev == EV_END && qmin > 0.0 && u.z > 0.0 && du.z * hlim * s <= 0.25 * u.z)
                f = FORM_W, e0 = c->y[PW], e1 = c->W_end, rate = u.z;
            if (f >= 0 && e1 > e0) {
                double he = h * s * rate;
                pd_ode_reset(ode);
                fresh = 1;
                pd_status st = pd_ode_step(ode, form_rhs[f], c, &e0, e1, &he, c->y);
                ++*nsteps;
                if (st == PD_ERR_NO_CONVERGENCE)
                    henon = 0; /* never seen; ordinary steps take over */
                else if (st != PD_OK)
                    return st;
                else if (e0 != e1)
                    h = he / (s * rate); /* the integrator shortened the step */
                continue;
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
        if (fresh)
            pd_ode_reset(ode); /* GSL reuses the last step's end derivative */
        fresh = 0;
        pd_status st = pd_ode_step(ode, rhs_tau, c, &tau, t1, &h, c->y);
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
            fresh = 1;
        }
    }
}
