/* contact_phase.c: sustained sliding contact as one continuous motion (see
 * contact_phase.h).
 *
 * Microcollisions (drop.c) stand in for a contact force by impulses a rest
 * fall apart; each one stops the contact where its step left it, so the
 * part sinks and is damped step by step (README: "Known limit"), and a part
 * sliding on an edge for a tenth of a second costs a hundred of them. While
 * one vertex or one edge slides on the floor, the exact motion is an ODE
 * instead: the normal forces lambda_i are those that keep each contact's
 * normal acceleration zero (a 1x1 or 2x2 linear system, since Coulomb
 * friction -mu lambda_i s_i along each contact's slip s_i is linear in
 * lambda_i), and friction does negative work only, so the energy can only
 * fall. The phase is integrated by the adaptive rk8pd of gsl_adapter in units
 * of the part (length L, time sqrt(L/g)), and ends, handing the state back
 * to the microcollisions, just before any of:
 *  - a normal force reaching zero (a contact lifts off),
 *  - a slip falling below PD_TOL_PHASE_SLIP_REL sqrt(g L) (sticking, rolling:
 *    the collision law decides what happens there),
 *  - another vertex reaching the floor (an impact),
 *  - the linear system losing positive definiteness (Painleve's paradox),
 * located by halving the step to PD_TOL_PHASE_EVENT_REL sqrt(L/g); and it
 * ends the drop when the energy test decides it. */
#include <math.h>
#include <string.h>
#include "contact_phase.h"
#include "drop_internal.h"
#include "gsl_adapter.h"
#include "posedrop/tolerances.h"
#include "quat.h"
#include "vec3.h"

enum { X = 0, V = 3, Q = 6, W = 10, NY = 13 };

typedef struct {
    const pd_body *b;
    int nc;
    int v[2];        /* contact vertices */
    double mu, g;
    double L, T;     /* units: length, time */
} phase;

pd_ode *pd_contact_phase_ode_alloc(void)
{
    return pd_ode_alloc(NY, PD_TOL_PHASE_ODE_REL, PD_TOL_PHASE_ODE_REL);
}

static void to_y(const phase *p, const pd_state *s, double y[NY])
{
    double V0 = p->L / p->T;
    const double c[NY] = {s->x.x / p->L, s->x.y / p->L, s->x.z / p->L, s->v.x / V0, s->v.y / V0,
                          s->v.z / V0, s->q.w, s->q.x, s->q.y, s->q.z, s->w.x * p->T,
                          s->w.y * p->T, s->w.z * p->T};
    memcpy(y, c, sizeof c);
}

static pd_state from_y(const phase *p, const double y[NY])
{
    double V0 = p->L / p->T;
    pd_state s;
    s.x = v3(y[X] * p->L, y[X + 1] * p->L, y[X + 2] * p->L);
    s.v = v3(y[V] * V0, y[V + 1] * V0, y[V + 2] * V0);
    s.q = quat_normalize(quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]));
    s.w = v3(y[W] / p->T, y[W + 1] / p->T, y[W + 2] / p->T);
    return s;
}

/* The contact forces of state s and the accelerations they give (SI).
 * Returns 0, or 1 when the phase's model does not hold at s: a slip too
 * small to give friction a direction, or a system that is not positive
 * definite (no unique force, Painleve). lambda and slip speeds are returned
 * for the exit tests. */
static int forces(const phase *p, const pd_state *s, pd_vec3 *acc, pd_vec3 *wdot, double lambda[2],
                  double slip[2])
{
    const pd_body *b = p->b;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    pd_vec3 w = s->w;
    pd_vec3 Iw = v3(b->moment[0] * w.x, b->moment[1] * w.y, b->moment[2] * w.z);
    pd_vec3 gyro = v3_cross(w, Iw);
    /* Angular acceleration without contact forces, and per unit lambda_j. */
    pd_vec3 a0 = v3(-b->inv_moment[0] * gyro.x, -b->inv_moment[1] * gyro.y, -b->inv_moment[2] * gyro.z);
    pd_vec3 dir[2], alpha[2];
    double A[2][2], rhs[2];
    for (int j = 0; j < p->nc; j++) {
        pd_vec3 r = b->verts[p->v[j]];
        pd_vec3 vc = v3_add(s->v, quat_rotate(s->q, v3_cross(w, r)));
        slip[j] = hypot(vc.x, vc.y);
        if (!(slip[j] > 0.0))
            return 1;
        dir[j] = v3(-p->mu * vc.x / slip[j], -p->mu * vc.y / slip[j], 1.0); /* world */
        pd_vec3 tb = v3_cross(r, quat_rotate_inv(s->q, dir[j]));
        alpha[j] = v3(b->inv_moment[0] * tb.x, b->inv_moment[1] * tb.y, b->inv_moment[2] * tb.z);
    }
    for (int i = 0; i < p->nc; i++) {
        pd_vec3 r = b->verts[p->v[i]];
        rhs[i] = p->g - v3_dot(up, v3_add(v3_cross(a0, r), v3_cross(w, v3_cross(w, r))));
        for (int j = 0; j < p->nc; j++)
            A[i][j] = 1.0 / b->mass + v3_dot(up, v3_cross(alpha[j], r));
    }
    if (p->nc == 1) {
        if (!(A[0][0] > 0.0))
            return 1;
        lambda[0] = rhs[0] / A[0][0];
    } else {
        /* Friction makes A unsymmetric; a positive diagonal and determinant
         * still give the unique solution continuous in the state. */
        double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
        if (!(A[0][0] > 0.0 && A[1][1] > 0.0 && det > 0.0))
            return 1;
        lambda[0] = (rhs[0] * A[1][1] - A[0][1] * rhs[1]) / det;
        lambda[1] = (A[0][0] * rhs[1] - A[1][0] * rhs[0]) / det;
    }
    pd_vec3 F = v3(0.0, 0.0, 0.0);
    *wdot = a0;
    for (int j = 0; j < p->nc; j++) {
        F = v3_add(F, v3_scale(dir[j], lambda[j]));
        *wdot = v3_add(*wdot, v3_scale(alpha[j], lambda[j]));
    }
    *acc = v3_add(v3_scale(F, 1.0 / b->mass), v3(0.0, 0.0, -p->g));
    return 0;
}

static int phase_rhs(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const phase *p = user;
    pd_state s = from_y(p, y);
    pd_vec3 acc, wdot;
    double lambda[2], slip[2];
    if (forces(p, &s, &acc, &wdot, lambda, slip))
        return 1;
    double T = p->T, V0 = p->L / T;
    pd_quat q = quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]);
    pd_quat dq = quat_mul(q, quat(0.0, y[W], y[W + 1], y[W + 2]));
    const double d[NY] = {y[V], y[V + 1], y[V + 2], acc.x * T / V0, acc.y * T / V0,
                          acc.z * T / V0, 0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z,
                          wdot.x * T * T, wdot.y * T * T, wdot.z * T * T};
    memcpy(dydt, d, sizeof d);
    return 0;
}

/* How far s is from the phase's end, in the part's units: the normal forces
 * (per unit weight), the slips above slip_min (per sqrt(g L)) and the height
 * of the lowest other vertex above the contacts (per L), into g[NMARGIN].
 * Each is a smooth function of the state, so an event inside a step is found
 * by the secant method on the one that crossed. Returns the smallest
 * (positive while the phase may go on), or -1 where the model fails (no
 * slip direction, no unique force). */
enum { NMARGIN = 5 };

static double margin(const phase *p, const pd_state *s, double slip_min, double g[NMARGIN])
{
    pd_vec3 acc, wdot;
    double lambda[2], slip[2];
    for (int k = 0; k < NMARGIN; k++)
        g[k] = HUGE_VAL;
    if (forces(p, s, &acc, &wdot, lambda, slip))
        return -1.0;
    const pd_body *b = p->b;
    double V0 = p->L / p->T, mg = b->mass * p->g;
    for (int i = 0; i < p->nc; i++) {
        g[i] = lambda[i] / mg;
        g[2 + i] = (slip[i] - slip_min) / V0;
    }
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    double floor_z = HUGE_VAL; /* the contacts' own height: they define the floor */
    for (int i = 0; i < p->nc; i++)
        floor_z = fmin(floor_z, s->x.z + v3_dot(up, b->verts[p->v[i]]));
    /* The next vertex to touch: while the contacts are the lowest, the
     * lowest other vertex is an edge neighbour of one of them (on a convex
     * polytope the vertices below any height are connected), and the margin
     * is continuous, so it crosses zero before any other vertex could. */
    for (int i = 0; i < p->nc; i++)
        for (int k = b->adj_start[p->v[i]]; k < b->adj_start[p->v[i] + 1]; k++) {
            int w = b->adj[k];
            if (w == p->v[0] || (p->nc == 2 && w == p->v[1]))
                continue;
            g[4] = fmin(g[4], (s->x.z + v3_dot(up, b->verts[w]) - floor_z) / p->L);
        }
    double least = HUGE_VAL;
    for (int k = 0; k < NMARGIN; k++)
        least = fmin(least, g[k]);
    return least;
}

/* Sets the contacts' normal velocities to zero by the frictionless impulses
 * that change the kinetic energy least: an orthogonal projection in the
 * mass metric, so the energy cannot rise whatever the impulses' signs.
 * Microcollisions leave resting contacts chattering at up to the rest speed;
 * a phase needs them exactly in contact. 0 if the system is singular. */
static int settle_normal(const pd_body *b, pd_state *s, const int *contacts, int nc)
{
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    pd_vec3 dw[2];
    double K[2][2], vn[2];
    for (int j = 0; j < nc; j++) {
        pd_vec3 t = v3_cross(b->verts[contacts[j]], up);
        dw[j] = v3(b->inv_moment[0] * t.x, b->inv_moment[1] * t.y, b->inv_moment[2] * t.z);
    }
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = b->verts[contacts[i]];
        vn[i] = s->v.z + v3_dot(up, v3_cross(s->w, r));
        for (int j = 0; j < nc; j++)
            K[i][j] = 1.0 / b->mass + v3_dot(up, v3_cross(dw[j], r));
    }
    double P[2];
    if (nc == 1) {
        if (!(K[0][0] > 0.0))
            return 0;
        P[0] = -vn[0] / K[0][0];
    } else {
        double det = K[0][0] * K[1][1] - K[0][1] * K[1][0];
        if (!(K[0][0] > 0.0 && det > 1e-12 * K[0][0] * K[1][1]))
            return 0;
        P[0] = (-vn[0] * K[1][1] + K[0][1] * vn[1]) / det;
        P[1] = (-vn[1] * K[0][0] + K[1][0] * vn[0]) / det;
    }
    for (int j = 0; j < nc; j++) {
        s->v.z += P[j] / b->mass;
        s->w = v3_add(s->w, v3_scale(dw[j], P[j]));
    }
    return 1;
}

int pd_contact_phase_start(const pd_sim_model *m, const pd_scene *sc, pd_state *s,
                           const int *contacts, int nc)
{
    if (nc < 1 || nc > 2)
        return 0;
    const pd_body *b = m->body;
    phase p = {b, nc, {contacts[0], nc > 1 ? contacts[1] : -1}, sc->mu, sc->gravity, b->size,
               sqrt(b->size / sc->gravity)};
    double vscale = sqrt(sc->gravity * b->size);
    pd_vec3 ww = quat_rotate(s->q, s->w);
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = quat_rotate(s->q, b->verts[contacts[i]]);
        if (fabs(s->v.z + v3_cross(ww, r).z) > m->v_rest)
            return 0; /* a flight or an impact, not chatter */
    }
    pd_state t = *s;
    double g[NMARGIN];
    if (!settle_normal(b, &t, contacts, nc) ||
        !(margin(&p, &t, 2.0 * PD_TOL_PHASE_SLIP_REL * vscale, g) > 0.0))
        return 0;
    *s = t;
    return 1;
}

pd_status pd_contact_phase(const pd_sim_model *m, pd_ode *ode, const pd_scene *sc, pd_state *s,
                           const int *contacts, int nc, double t_max, double *t_used)
{
    const pd_body *b = m->body;
    phase p = {b, nc, {contacts[0], nc > 1 ? contacts[1] : -1}, sc->mu, sc->gravity, b->size,
               sqrt(b->size / sc->gravity)};
    double slip_min = PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    double tau = 0.0, tau_max = t_max / p.T, h = 0.01, cap = INFINITY;
    double y[NY], y0[NY];
    int hint = 0, pose;
    to_y(&p, s, y);
    double g0[NMARGIN], g1[NMARGIN];
    double least = margin(&p, s, slip_min, g0);
    pd_ode_reset(ode);
    for (int step = 0; step < PD_PHASE_MAX_STEPS && tau < tau_max && least > 0.0; step++) {
        double tau0 = tau, h_try = h;
        memcpy(y0, y, sizeof y);
        double t1 = fmin(tau_max, tau + fmin(cap, 10.0 * h));
        pd_status st = pd_ode_step(ode, phase_rhs, &p, &tau, t1, &h, y);
        double len = st == PD_OK ? tau - tau0 : fmin(t1 - tau0, h_try);
        pd_state n = from_y(&p, y);
        double least1 = st == PD_OK ? margin(&p, &n, slip_min, g1) : -1.0;
        if (least1 > 0.0) {
            /* Keep the quaternion on the unit sphere between steps. */
            y[Q] = n.q.w, y[Q + 1] = n.q.x, y[Q + 2] = n.q.y, y[Q + 3] = n.q.z;
            *s = n;
            memcpy(g0, g1, sizeof g0);
            least = least1;
            cap = INFINITY;
            if (pd_drop_decided(m, s, sc->gravity, &hint, &pose) > 0)
                break;
            continue;
        }
        if (st != PD_OK && st != PD_ERR_INTERNAL && st != PD_ERR_NO_CONVERGENCE)
            return st;
        /* An event inside the step: back to its start and retry up to the
         * secant estimate of the first crossing among the margins that
         * crossed (regula falsi from the step's start, which the margins
         * being smooth makes converge in a few retries); a failed step or a
         * model failure halves it. When the crossing is within the event
         * tolerance, hand over. */
        tau = tau0;
        memcpy(y, y0, sizeof y);
        pd_ode_reset(ode);
        double frac = 0.5;
        if (least1 > -1.0) {
            frac = 1.0;
            for (int k = 0; k < NMARGIN; k++)
                if (g1[k] <= 0.0)
                    frac = fmin(frac, g0[k] / (g0[k] - g1[k]));
        }
        if (len * frac <= PD_TOL_PHASE_EVENT_REL)
            break;
        cap = len * fmax(0.01, 0.99 * frac);
        h = cap;
    }
    *t_used = tau * p.T;
    return PD_OK;
}
