/* impact_slide.c: a collision's sliding phase, eq. 14 integrated in tau by
 * its Taylor series between events, and onto an event by one step of a
 * Runge-Kutta pair (GSL's rk8pd if the fifth-order one is refused) in the
 * event's own variable (see impact_collision.h).
 *
 * Eq. 14 gives p and W as functions of pz. The integrator runs in a
 * parameter sigma of our choosing, with dpz/dsigma = g > 0 along the
 * trajectory: a change of step measure, so every choice has the same
 * solutions. The state is (px, py, pz, W) in every form, W integrated only
 * under the energetic law. */
#include <math.h>
#include "impact/impact_collision.h"
#include "impact/impact_slide.h"
#include "impact/impact_tol.h"

enum {
    FORM_PZ,  /* g = 1: sigma = pz, one step onto Poisson's end */
    FORM_UZ,  /* g = 1 / (du_z/dpz): sigma = u_z, one step onto maximum compression */
    FORM_W    /* g = 1 / u_z: sigma = W, one step onto the energetic end */
};

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

static const pd_ode_fn form_rhs[] = {rhs_pz, rhs_uz, rhs_w};

/* The step in tau assumed before the first Taylor step sets its own, in
 * units of the flow's rate: u_t' = |u_t| a - mu B u_t changes at most at
 * |a| + mu |B| (Frobenius norm) per unit tau. An event ahead within it is
 * landed on by one step in its own variable (henon_form). 0.3 is about
 * rk8pd's first accepted step at 1e-11 (measured). */
#define TAU_FIRST_STEP 0.3

/* Incoming rays are looked for once the slip falls below this (units of
 * |u0|): the snap onto one needs the slip near the origin or on the ray
 * exactly, and 2k instructions are saved where it never comes near. The
 * tail's series would take over at any slip, but a slide that comes within
 * its reach at a slip above this is rare and short: measured on the
 * recorded drops and random impacts, 0.3 took 0-7% fewer steps than 0.1
 * but 0.1-1.5% more instructions. */
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

/* The end of the collision within the event tolerance (Poisson's pz_end, or
 * the energetic W_end): the gap closed along the current impulse direction
 * d, to second order in it. Returns 1 if it ended. */
static int close_end(collision *c, pd_vec3 u, pd_vec3 d)
{
    if (!c->compressed)
        return 0;
    if (c->law == PD_IMPACT_POISSON) {
        if (c->y[PZ] < c->pz_end - PD_TOL_IMPACT_EVENT_REL * c->pz_end)
            return 0;
        linear_advance(c, d, 0.0, u.z, c->pz_end - c->y[PZ]);
        c->y[PZ] = c->pz_end;
    } else {
        if (c->y[PW] < c->W_end - PD_TOL_IMPACT_EVENT_REL * fabs(c->W_c))
            return 0;
        /* W + u_z h + q h^2 / 2 = W_end: left open, the tolerance on W would
         * stay in pz as an error of tolw / u_z, large when e is small. */
        double q = m3_vec(CONST_M3(c->K), d).z, gap = work_step(u.z, q, c->W_end - c->y[PW]);
        if (isfinite(gap)) {
            linear_advance(c, d, q, u.z, gap);
            c->y[PW] = c->W_end;
        }
    }
    c->done = 1;
    return 1;
}

enum { RAY_NONE, RAY_STUCK, RAY_MOVED };

/* Onto an incoming ray: within the event tolerance of one the trajectory is
 * on it for good (p' = (-mu t, 1), closed form) up to the slip reaching the
 * origin or a normal event, whichever is first; near one, the rest of the
 * slide is the ray's tail (impact_ray_series.c) if no normal event lies in it.
 * Integrating on instead is stiff: the direction relaxes onto the ray far
 * faster than |u_t| shrinks (measured: 1 in 1e5 random impacts exceeded
 * PD_IMPACT_MAX_STEPS), and costs a step per halving of the slip. Returns
 * RAY_STUCK (the slide is over), RAY_MOVED (the state jumped to a normal
 * event on the ray) or RAY_NONE. */
static int onto_incoming(collision *c, pd_vec3 u, double s)
{
    const double tols = PD_TOL_IMPACT_EVENT_REL; /* |u0| = 1 */
    const double tolz = PD_TOL_IMPACT_EVENT_REL * fabs(c->u0.z);
    for (int k = 0; k < c->in.n; k++) {
        const double tx = c->in.tx[k], ty = c->in.ty[k];
        if (!(u.x * tx + u.y * ty > 0.0) || !(fabs(tx * u.y - ty * u.x) <= tols))
            continue;
        pd_vec3 d = v3(-c->mu * tx, -c->mu * ty, 1.0);
        double q = m3_vec(CONST_M3(c->K), d).z;
        double hs = s / -c->in.rate[k], he = INFINITY;
        if (!c->compressed && q > 0.0)
            he = -u.z / q;
        else if (c->compressed && c->law == PD_IMPACT_POISSON)
            he = c->pz_end - c->y[PZ];
        else if (c->compressed && q > 0.0)
            he = c->W_end > c->y[PW] ? work_step(u.z, q, c->W_end - c->y[PW]) : 0.0;
        he = fmax(he, 0.0);
        linear_advance(c, d, q, u.z, fmin(hs, he));
        /* stuck: what is left of the slip is the ray's offset, <= tols */
        return hs <= he ? RAY_STUCK : RAY_MOVED;
    }
    /* The tail, if its error is a tenth of the event tolerance (of the
     * impulse, |u0|/K = 1 here): sticking declared at |u_t| = tols leaves
     * out more, tols / |rate| of it. It takes over at any slip; each ray's
     * series is built the first time the slip comes within its angle. */
    const int work = c->law == PD_IMPACT_ENERGETIC;
    for (int k = 0; k < c->in.n; k++) {
        pd_vec3 dp;
        double dw;
        const double tx = c->in.tx[k], ty = c->in.ty[k];
        if (!(c->built & 1u << k) && u.x * tx + u.y * ty > 0.0 &&
            fabs(tx * u.y - ty * u.x) <= PD_TOL_IMPACT_SERIES_ANGLE * (u.x * tx + u.y * ty)) {
            pd_ray_series_build(CONST_M3(c->K), c->mu, tx, ty, work, &c->ser[k]);
            c->built |= 1u << k;
        }
        if (!(c->built & 1u << k &&
              pd_ray_series_tail(CONST_M3(c->K), c->mu, &c->ser[k], u, PD_TOL_IMPACT_SERIES_ANGLE,
                                 PD_TOL_IMPACT_TAIL_REL, work, &dp, &dw)))
            continue;
        /* u_z and W rise monotonically along it: an event is at its end. */
        int event = !c->compressed ? u.z + m3_vec(CONST_M3(c->K), dp).z >= -tolz
                  : c->law == PD_IMPACT_POISSON
                        ? c->y[PZ] + dp.z >= c->pz_end - PD_TOL_IMPACT_EVENT_REL * c->pz_end
                        : c->y[PW] + dw >= c->W_end - PD_TOL_IMPACT_EVENT_REL * fabs(c->W_c);
        if (event)
            continue;
        c->y[PX] += dp.x;
        c->y[PY] += dp.y;
        c->y[PZ] += dp.z;
        c->y[PW] += dw;
        return RAY_STUCK;
    }
    return RAY_NONE;
}

/* The tail onto the diverging ray is tried only when the next normal event
 * lies more than this many of the current steps ahead (its Newton estimate
 * in tau): nearer, a step or two reach it for less than the series' build
 * and root (about 2k instructions each, a Taylor step 1.8k). Measured on
 * 400 drops each of the box and the cap (callgrind, the impacts' share):
 * 0, 2, 4, 8, 16 gave 40.3M, 40.1M, 39.9M, 39.7M, 39.8M (box) and 230M,
 * 229M, 228M, 228M, 232M (cap), tails tried within 1 rad; the cube's
 * best was 4. It changes which of two paths of the same tolerance a slide
 * takes, not the tolerance. */
#define TAIL_AFTER 4.0

/* The tail onto the diverging ray is built and tried within this angle
 * (rad) of the ray. Its error bound (pd_ray_out_tail) decides whether it is
 * used, so the angle bounds the cost, not the error: farther out its
 * 12-term series rarely meet PD_TOL_IMPACT_TAIL_REL and the build and the
 * refused root are wasted. Measured on 400 drops each (callgrind, the
 * impacts' instructions; box, cap, cube): 0.05: 41.0M, 262M, 40.8M; 0.1:
 * 40.6M, 249M, 40.2M; 0.15: 40.3M, 244M, 39.9M; 0.2: 40.5M, 243M, 40.0M;
 * 0.4: 41.1M, 249M, 40.6M; 1: 41.9M, 255M, 41.5M (16 terms at 0.4: 40.5M,
 * 243M, 40.0M; 20 terms: more). */
#define OUT_ANGLE 0.2

/* Onto the diverging ray, under Poisson's law (the energetic law's work is
 * not in the series): within OUT_ANGLE of the ray the
 * rest of the slide up to the next normal event is a closed form in power
 * series (pd_ray_out_tail), where stepping took a step per factor of about
 * two in the slip while the direction settled onto the ray. The slip's
 * direction only approaches the ray, so a tail refused (its truncation
 * above PD_TOL_IMPACT_TAIL_REL, or u_z not rising all the way) is tried
 * again only once the angle has halved. Returns 1 if the state jumped to
 * the event. */
static int onto_diverging(collision *c, pd_vec3 u)
{
    const double dot = u.x * c->rtx + u.y * c->rty, crs = c->rtx * u.y - c->rty * u.x;
    if (c->law != PD_IMPACT_POISSON || !(dot > 0.0) ||
        !(fabs(crs) <= OUT_ANGLE * dot) ||
        (c->out_refused > 0.0 && !(fabs(crs) <= 0.5 * c->out_refused * dot)))
        return 0;
    if (!c->out_built) {
        pd_ray_out_build(CONST_M3(c->K), c->mu, c->rtx, c->rty, c->out);
        c->out_built = 1;
    }
    pd_vec3 dp;
    const int target = c->compressed ? PD_RAY_OUT_PZ : PD_RAY_OUT_COMPRESS;
    const double ev = PD_TOL_IMPACT_EVENT_REL * (c->compressed ? c->pz_end : fabs(c->u0.z));
    if (!pd_ray_out_tail(CONST_M3(c->K), c->mu, c->out, u, target, c->pz_end - c->y[PZ], ev,
                         OUT_ANGLE, PD_TOL_IMPACT_TAIL_REL, &dp)) {
        c->out_refused = fabs(crs) / dot;
        return 0;
    }
    c->y[PX] += dp.x;
    c->y[PY] += dp.y;
    c->y[PZ] += dp.z;
    return 1;
}

/* Henon's trick: an event within the integrator's next step is landed on
 * by one step in its own variable, which ends exactly there, instead of by
 * Newton steps that each leave a residual (two or three steps an event).
 * Only where that variable is a smooth parameter all along the step: the
 * slip stays away from zero (by the Newton estimate it cannot fall below
 * half), and the variable's rate away from zero: q = du_z/dpz > 1/4 of its
 * value here for every direction, u_z > 4 times its growth over the step.
 * qmin is q's least over directions, K_zz - mu |K_zt|.
 * Returns the form to step in and sets its range [*e0, *e1] and *rate =
 * dsigma/dpz here, or -1. */
static int henon_form(const collision *c, double qmin, int ev, pd_vec3 u, double s, pd_vec3 du,
                      double hlim, double *e0, double *e1, double *rate)
{
    if ((u.x * du.x + u.y * du.y) * hlim < -0.5 * s)
        return -1;
    if (ev == EV_COMPRESS && qmin > 0.25 * du.z) {
        *e0 = u.z, *e1 = 0.0, *rate = du.z;
        return FORM_UZ;
    }
    if (ev == EV_END && c->law == PD_IMPACT_POISSON) {
        *e0 = c->y[PZ], *e1 = c->pz_end, *rate = 1.0;
        return FORM_PZ;
    }
    if (ev == EV_END && qmin > 0.0 && u.z > 0.0 && du.z * hlim * s <= 0.25 * u.z) {
        *e0 = c->y[PW], *e1 = c->W_end, *rate = u.z;
        return FORM_W;
    }
    return -1;
}

/* Dormand and Prince's fifth-order pair (its fourth-order partner as the
 * error estimate): the nodes, the stages' weights, the fifth-order weights
 * (also the last stage's), and the difference of the two orders' weights. */
static const double DP_C[7] = {0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0};
static const double DP_A[6][6] = {
    {1.0 / 5.0},
    {3.0 / 40.0, 9.0 / 40.0},
    {44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0},
    {19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0},
    {9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0},
    {35.0 / 384.0, 0.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0}};
static const double DP_E[7] = {71.0 / 57600.0, 0.0, -71.0 / 16695.0, 71.0 / 1920.0,
                               -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0};

/* One step of that pair across the whole event interval [e0, e1] of a
 * Henon form, tried before rk8pd's: most events are reached by a step across
 * which the sliding direction barely turns (a microcollision's slip far
 * above its approach speed), where the pair meets the integrator's own
 * tolerance (the same absolute and relative bound on each component) at 7
 * evaluations, not 13, and less arithmetic than GSL's stepper. The event's
 * variable is linear in the state with rate 1 in its own form, which a
 * Runge-Kutta step keeps exactly, so the step lands on the event as rk8pd's
 * does. Refused (0, state untouched) when the estimate exceeds the
 * tolerance or a stage is not finite; the caller then steps as before. */
static int low_order_event_step(collision *c, pd_ode_fn fn, double e0, double e1,
                                const double k1[])
{
    const int n = c->law == PD_IMPACT_ENERGETIC ? NSTATE : NSTATE_P;
    const double h = e1 - e0;
    double k[7][NSTATE], y[NSTATE];
    for (int i = 0; i < NSTATE; i++) {
        k[0][i] = k1[i];
        y[i] = c->y[i];
    }
    for (int st = 1; st < 7; st++) {
        for (int i = 0; i < n; i++) {
            double dy = 0.0;
            for (int j = 0; j < st; j++)
                dy += DP_A[st - 1][j] * k[j][i];
            y[i] = c->y[i] + h * dy;
        }
        fn(e0 + DP_C[st] * h, y, k[st], c);
    }
    /* y is now the fifth-order solution, the last stage's argument. */
    for (int i = 0; i < n; i++) {
        double err = 0.0;
        for (int j = 0; j < 7; j++)
            err += DP_E[j] * k[j][i];
        err *= h;
        if (!isfinite(y[i]) || !(fabs(err) <= c->tol * (1.0 + fabs(y[i]))))
            return 0;
    }
    for (int i = 0; i < n; i++)
        c->y[i] = y[i];
    return 1;
}

/* Every ordinary step is of eq. 14 in tau, dpz/dtau = |u_t|:
 * p' = (-mu u_x, -mu u_y, |u_t|), W' = u_z |u_t| (taylor_step). Its
 * right-hand side is Lipschitz: nothing is divided by |u_t|, and the origin
 * of the tangential plane becomes a rest point approached exponentially in
 * tau instead of a singularity reached at a finite pz. In pz the flow near
 * the origin turns the sliding direction at a rate ~1/|u_t| (stiff: an
 * explicit step must shrink with |u_t|); in tau it turns at a bounded
 * rate, and a trajectory cannot step over the origin. Integrating in pz where the slip
 * is large did not pay: rk8pd's steps there are as long in pz as in tau
 * (the turning of the direction sets both), and were refused more often.
 *
 * Order of the Taylor step in tau: lower orders take more steps, higher
 * ones cost more per step (its convolutions grow as the order squared) than
 * they save; 16 took the fewest instructions on the impacts of recorded
 * drops, within the tolerance (docs/performance.md, the Taylor step). */
#define TAYLOR_ORDER 16

/* The Taylor step's length is this share of the one at which its last two
 * terms reach the tolerance: a series of radius R has terms falling as
 * (h/R)^k, so a step a tenth inside that keeps the omitted tail below the
 * last term kept (taylor_step). */
#define TAYLOR_SAFETY 0.9

/* The Taylor series of the tau flow at a state y (taylor_coefs) and the
 * step it allows (h): kept across a step that overshot an event, which is
 * retried from the same state with the same series and only a shorter h. */
typedef struct {
    double y[NSTATE]; /* the state it was built at */
    int valid;
    double P[3][TAYLOR_ORDER + 1], W[TAYLOR_ORDER + 1];
    double h;
} taylor_series;

/* The series of the tau flow at the current state. The coefficients follow
 * from the flow: p_t' = -mu u_t, pz' = s, W' = u_z s, u = u0 + K p (so u's
 * coefficients are K times p's), and s's from s^2 = u_x^2 + u_y^2:
 * 2 s_0 s_m = sum_{j=0..m} (x_j x_{m-j} + y_j y_{m-j}) - sum_{j=1..m-1} s_j s_{m-j}.
 * The step is the longest at which each of the last two terms stays within
 * the tolerance c->tol (1 + |y_i|) of every component, a tenth shorter:
 * the terms of a series of radius R fall as (h/R)^k, so the omitted tail is
 * below the last term once h is well inside R. */
static void taylor_coefs(const collision *c, taylor_series *T)
{
    const int work = c->law == PD_IMPACT_ENERGETIC, N = TAYLOR_ORDER;
    double (*P)[TAYLOR_ORDER + 1] = T->P, *W = T->W;
    double X[TAYLOR_ORDER + 1], Y[TAYLOR_ORDER + 1], Z[TAYLOR_ORDER + 1], S[TAYLOR_ORDER + 1];
    for (int i = 0; i < NSTATE; i++)
        T->y[i] = c->y[i];
    T->valid = 1;
    for (int i = 0; i < 3; i++)
        P[i][0] = c->y[i];
    W[0] = c->y[PW];
    pd_vec3 u = coll_u(c, c->y);
    X[0] = u.x, Y[0] = u.y, Z[0] = u.z;
    S[0] = sqrt(u.x * u.x + u.y * u.y);
    for (int k = 0; k < N; k++) {
        const int m = k + 1;
        const double r = 1.0 / m;
        P[0][m] = -c->mu * X[k] * r;
        P[1][m] = -c->mu * Y[k] * r;
        P[2][m] = S[k] * r;
        X[m] = c->K[0][0] * P[0][m] + c->K[0][1] * P[1][m] + c->K[0][2] * P[2][m];
        Y[m] = c->K[1][0] * P[0][m] + c->K[1][1] * P[1][m] + c->K[1][2] * P[2][m];
        /* the sum's terms pair up, j with m - j */
        double acc = 0.0;
        for (int j = 1; 2 * j < m; j++)
            acc += X[j] * X[m - j] + Y[j] * Y[m - j] - S[j] * S[m - j];
        acc = 2.0 * (acc + X[0] * X[m] + Y[0] * Y[m]);
        if (m % 2 == 0)
            acc += X[m / 2] * X[m / 2] + Y[m / 2] * Y[m / 2] - S[m / 2] * S[m / 2];
        S[m] = acc / (2.0 * S[0]);
        if (work) {
            Z[m] = c->K[2][0] * P[0][m] + c->K[2][1] * P[1][m] + c->K[2][2] * P[2][m];
            double w = 0.0;
            for (int j = 0; j <= k; j++)
                w += Z[j] * S[k - j];
            W[m] = w * r;
        }
    }
    double r1 = 0.0, r0 = 0.0; /* the last two terms' largest ratio to their tolerance */
    for (int i = 0; i < (work ? NSTATE : NSTATE_P); i++) {
        const double *a = i < 3 ? P[i] : W;
        double tol = c->tol * (1.0 + fabs(a[0]));
        r1 = fmax(r1, fabs(a[N - 1]) / tol);
        r0 = fmax(r0, fabs(a[N]) / tol);
    }
    T->h = TAYLOR_SAFETY * fmin(r1 > 0.0 ? pow(r1, -1.0 / (N - 1)) : HUGE_VAL,
                                r0 > 0.0 ? pow(r0, -1.0 / N) : HUGE_VAL);
}

/* One step of the tau flow by its Taylor series at the current state, to
 * tau + min(t1 - tau, the series' own step), the series built unless T holds
 * it for this state already. *hnext is the series' own step. */
static void taylor_step(collision *c, taylor_series *T, double *tau, double t1, double *hnext)
{
    const int work = c->law == PD_IMPACT_ENERGETIC, N = TAYLOR_ORDER;
    int same = T->valid;
    for (int i = 0; i < NSTATE && same; i++)
        same = T->y[i] == c->y[i];
    if (!same)
        taylor_coefs(c, T);
    double h = T->h;
    *hnext = h;
    int last = !(h < t1 - *tau);
    if (last)
        h = t1 - *tau;
    for (int i = 0; i < (work ? NSTATE : NSTATE_P); i++) {
        const double *a = i < 3 ? T->P[i] : T->W;
        double v = a[N];
        for (int k = N - 1; k >= 0; k--)
            v = v * h + a[k];
        c->y[i] = v;
    }
    *tau = last ? t1 : *tau + h;
}

pd_status pd_impact_slide(collision *c, pd_ode *ode, int *nsteps)
{
    const double tols = PD_TOL_IMPACT_EVENT_REL; /* |u0| = 1 */
    const double tolz = PD_TOL_IMPACT_EVENT_REL * fabs(c->u0.z);
    double flow = c->mu * sqrt(c->K[0][0] * c->K[0][0] + 2.0 * c->K[0][1] * c->K[0][1] +
                               c->K[1][1] * c->K[1][1]) + hypot(c->K[0][2], c->K[1][2]);
    double tau = 0.0, h = TAU_FIRST_STEP / flow;
    const double qmin = c->K[2][2] - c->mu * hypot(c->K[2][0], c->K[2][1]); /* q's least */
    double cap = INFINITY; /* set by an overshoot: the next step ends there */
    int cap_event = EV_NONE;
    int henon = 1; /* cleared if a step onto an event ever fails */
    c->in.n = -1;  /* not looked for yet */
    pd_ray_series ser[PD_RAYS_MAX];
    c->ser = ser;
    pd_ray_out out;
    c->out = &out;
    taylor_series T;
    T.valid = 0;
    for (;;) {
        pd_vec3 u = coll_u(c, c->y);
        double s = sqrt(u.x * u.x + u.y * u.y);
        if (!c->compressed && u.z >= -tolz)
            coll_compress(c);
        if (c->done)
            return PD_OK;
        /* The impulse's direction now. */
        pd_vec3 d = s > 0.0 ? v3(-c->mu * u.x / s, -c->mu * u.y / s, 1.0) : v3(0.0, 0.0, 1.0);
        if (close_end(c, u, d))
            return PD_OK;
        if (s <= tols)
            return PD_OK; /* stuck */
        /* Within the event tolerance of the diverging ray the trajectory is
         * on it for good: the ray attracts nearby directions, and along it p'
         * is constant (closed form). Integrating instead is stiff: when the
         * ray's outward speed is small the direction relaxes onto the ray
         * far faster than |u_t| grows (measured: > 1000 steps). The slip's
         * direction can be that close to an invariant ray only where its
         * turning rate b (u_t x u_t' = s^2 b in tau) is at most the angle,
         * (pi/2) tols / s, times b's largest slope, |a| + mu (B's
         * eigenvalues' spread) <= flow (PD_IMPACT_ON_RAY_MARGIN); elsewhere no ray is
         * looked for on this account. */
        const int near_ray =
            !(fabs(u.x * (s * c->K[1][2] - c->mu * (c->K[1][0] * u.x + c->K[1][1] * u.y)) -
                   u.y * (s * c->K[0][2] - c->mu * (c->K[0][0] * u.x + c->K[0][1] * u.y))) >
              PD_IMPACT_ON_RAY_MARGIN * flow * tols * s);
        if (near_ray && coll_have_ray(c) && u.x * c->rtx + u.y * c->rty > 0.0 &&
            fabs(c->rtx * u.y - c->rty * u.x) <= tols) {
            c->on_ray = 1;
            return PD_OK;
        }
        /* A slide bound for the diverging ray can reach no incoming one,
         * nor come within the event tolerance of one away from the rays:
         * their search is left until it could be used. */
        if (c->in.n < 0 && s < RAYS_SLIP &&
            (near_ray || !coll_have_ray(c) ||
             !pd_ray_in_basin(CONST_M3(c->K), c->mu, c->rtx, c->rty, u, s)))
            pd_rays_incoming(CONST_M3(c->K), c->mu, &c->in);
        int ray = onto_incoming(c, u, s);
        if (ray != RAY_NONE) {
            ++*nsteps;
            if (ray == RAY_STUCK)
                return PD_OK;
            continue;
        }
        if (*nsteps >= PD_IMPACT_MAX_STEPS)
            return PD_ERR_NO_CONVERGENCE;

        pd_vec3 du = m3_vec(CONST_M3(c->K), d);
        double hlim, e0, e1, rate;
        int ev = next_event(c, u, s, du, &hlim);
        int f = henon && ev != EV_NONE && isinf(cap) && hlim <= h
                    ? henon_form(c, qmin, ev, u, s, du, hlim, &e0, &e1, &rate) : -1;
        if (f >= 0 && e1 > e0) {
            double he = h * s * rate, dy[NSTATE];
            form_rhs[f](e0, c->y, dy, c);
            if (low_order_event_step(c, form_rhs[f], e0, e1, dy)) {
                ++*nsteps;
                continue;
            }
            pd_status st = pd_ode_step_from(ode, form_rhs[f], c, &e0, e1, &he, c->y, dy);
            ++*nsteps;
            if (st == PD_ERR_NO_CONVERGENCE)
                henon = 0; /* never seen; ordinary steps take over */
            else if (st != PD_OK)
                return st;
            else if (e0 != e1)
                h = he / (s * rate); /* the integrator shortened the step */
            continue;
        }

        /* No step onto an event: the tail onto the diverging ray, where it
         * takes over, replaces the steps that would reach one. */
        if (!(hlim <= TAIL_AFTER * h) && coll_have_ray(c) && onto_diverging(c, u)) {
            ++*nsteps;
            cap = INFINITY;
            cap_event = EV_NONE;
            continue;
        }
        if (cap < hlim) {
            hlim = cap;
            ev = cap_event;
        }
        /* No event ahead: let the step grow (a Taylor step longer than 10 h
         * is only cut short). */
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
        /* The step is given the derivative at its start, evaluates none at
         * its end and keeps no history, so the jumps of the state between
         * steps (closed forms, retries) need no restart. */
        taylor_step(c, &T, &tau, t1, &h);
        ++*nsteps;
        cap = INFINITY;
        cap_event = EV_NONE;

        /* Overshoot: an event passed inside the step is bracketed and the
         * step retried to the secant estimate of its position. */
        double frac = INFINITY;
        int fev = EV_NONE;
        if (!c->compressed) {
            double uz = coll_u(c, c->y).z;
            if (uz > tolz)
                frac = -u.z / (uz - u.z), fev = EV_COMPRESS;
        } else if (c->law == PD_IMPACT_POISSON) {
            if (c->y[PZ] > c->pz_end + PD_TOL_IMPACT_EVENT_REL * c->pz_end)
                frac = (c->pz_end - y_a[PZ]) / (c->y[PZ] - y_a[PZ]), fev = EV_END;
        } else if (c->y[PW] > c->W_end + PD_TOL_IMPACT_EVENT_REL * fabs(c->W_c)) {
            frac = (c->W_end - y_a[PW]) / (c->y[PW] - y_a[PW]), fev = EV_END;
        }
        if (fev != EV_NONE) {
            cap = frac * (tau - tau_a);
            cap_event = fev;
            tau = tau_a;
            for (int i = 0; i < NSTATE; i++)
                c->y[i] = y_a[i];
        }
    }
}
