/* contact_phase.c: sustained contact as one continuous motion (see
 * contact_phase.h).
 *
 * Microcollisions (drop.c) stand in for a contact force by impulses a rest
 * fall apart; each one stops the contact where its step left it, so the
 * part sinks and is damped step by step (README: "Known limit"), and a part
 * sliding or rolling for a tenth of a second costs a hundred of them. While
 * one vertex or one edge touches the floor, the exact motion is an ODE
 * instead. Each contact either slides, with force lambda (n - mu s) along its
 * slip s (one unknown, its normal acceleration held at zero), or sticks, with
 * a force f of three unknowns holding its whole acceleration at zero. The
 * forces solve a small linear system (at most 6 unknowns); two sticking
 * contacts (a rotation about an edge) leave the squeeze along the edge
 * undetermined, and the system takes the solution without it (least norm).
 * Sliding friction does negative work and sticking contacts none, so the
 * energy can only fall. The ODE is integrated by gsl_adapter's rk8pd in units
 * of the part (length L, time sqrt(L/g)); the phase ends, handing the state
 * back to the microcollisions, just before any of:
 *  - a normal force reaching zero (a contact lifts off),
 *  - a sliding contact's slip falling below PD_TOL_PHASE_SLIP_REL sqrt(g L),
 *  - a sticking contact's force leaving the friction cone (it starts to slip),
 *  - another vertex reaching the floor (an impact),
 *  - the system becoming singular (as in Painleve's paradox),
 * located by the secant method on the margin that crossed, to
 * PD_TOL_PHASE_EVENT_REL sqrt(L/g); and it ends the drop when the energy test
 * decides it. */
#include <math.h>
#include <string.h>
#include "contact_phase.h"
#include "drop_internal.h"
#include "gsl_adapter.h"
#include "phase_forces.h"
#include "posedrop/tolerances.h"
#include "quat.h"
#include "vec3.h"

enum { X = 0, V = 3, Q = 6, W = 10, NY = 13 };

pd_ode *pd_contact_phase_ode_alloc(void)
{
    return pd_ode_alloc(NY, PD_TOL_PHASE_ODE_REL, PD_TOL_PHASE_ODE_REL);
}

static void to_y(const pd_phase *p, const pd_state *s, double y[NY])
{
    double V0 = p->L / p->T;
    const double c[NY] = {s->x.x / p->L, s->x.y / p->L, s->x.z / p->L, s->v.x / V0, s->v.y / V0,
                          s->v.z / V0, s->q.w, s->q.x, s->q.y, s->q.z, s->w.x * p->T,
                          s->w.y * p->T, s->w.z * p->T};
    memcpy(y, c, sizeof c);
}

static pd_state from_y(const pd_phase *p, const double y[NY])
{
    double V0 = p->L / p->T;
    pd_state s;
    s.x = v3(y[X] * p->L, y[X + 1] * p->L, y[X + 2] * p->L);
    s.v = v3(y[V] * V0, y[V + 1] * V0, y[V + 2] * V0);
    s.q = quat_normalize(quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]));
    s.w = v3(y[W] / p->T, y[W + 1] / p->T, y[W + 2] / p->T);
    return s;
}

static int phase_rhs(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const pd_phase *p = user;
    pd_state s = from_y(p, y);
    pd_phase_forces F;
    if (pd_phase_forces_of(p, &s, &F))
        return 1;
    pd_vec3 acc = F.acc, wdot = F.wdot;
    double T = p->T, V0 = p->L / T;
    pd_quat q = quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]);
    pd_quat dq = quat_mul(q, quat(0.0, y[W], y[W + 1], y[W + 2]));
    const double d[NY] = {y[V], y[V + 1], y[V + 2], acc.x * T / V0, acc.y * T / V0,
                          acc.z * T / V0, 0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z,
                          wdot.x * T * T, wdot.y * T * T, wdot.z * T * T};
    memcpy(dydt, d, sizeof d);
    return 0;
}

/* How far s is from the phase's end, in the part's units: per contact its
 * normal force and, sticking, its force's distance inside the friction cone
 * (per unit weight) or, sliding, its slip above slip_min (per sqrt(g L));
 * and the height of the lowest other vertex above the contacts (per L); into
 * g[NMARGIN]. Each is a smooth function of the state, so an event inside a
 * step is found by the secant method on the one that crossed. Returns the
 * smallest (positive while the phase may go on), or -1 where the model
 * fails. */
enum { NMARGIN = 5 };

static double margin(const pd_phase *p, const pd_state *s, double slip_min, double g[NMARGIN])
{
    pd_phase_forces F;
    for (int k = 0; k < NMARGIN; k++)
        g[k] = HUGE_VAL;
    if (pd_phase_forces_of(p, s, &F))
        return -1.0;
    const pd_body *b = p->b;
    double V0 = p->L / p->T, mg = b->mass * p->g;
    for (int i = 0; i < p->nc; i++) {
        g[i] = F.fn[i] / mg;
        g[2 + i] = p->mode[i] == PD_PHASE_STICK ? F.cone[i] / mg : (F.slip[i] - slip_min) / V0;
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

static double kinetic(const pd_body *b, const pd_state *s)
{
    return 0.5 * b->mass * v3_dot(s->v, s->v) +
           0.5 * (b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                  b->moment[2] * s->w.z * s->w.z);
}

/* The phase for contacts[0..nc) of state s, each contact sliding if its
 * slip is above twice the end threshold, else sticking. */
static void phase_of(pd_phase *p, const pd_sim_model *m, const pd_scene *sc, const pd_state *s,
                     const int *contacts, int nc)
{
    const pd_body *b = m->body;
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    pd_phase_init(p, b, sc->gravity, sc->mu, s, contacts, nc, slip_start);
}

int pd_contact_phase_start(const pd_sim_model *m, const pd_scene *sc, pd_state *s,
                           const int *contacts, int nc)
{
    if (nc < 1 || nc > 2)
        return 0;
    const pd_body *b = m->body;
    pd_vec3 ww = quat_rotate(s->q, s->w);
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = quat_rotate(s->q, b->verts[contacts[i]]);
        if (fabs(s->v.z + v3_cross(ww, r).z) > m->v_rest)
            return 0; /* a flight or an impact, not chatter */
    }
    pd_phase p;
    phase_of(&p, m, sc, s, contacts, nc);
    for (int i = 0; i < nc; i++)
        if (p.mode[i] == PD_PHASE_STICK && sc->mu == 0.0)
            return 0; /* nothing holds a contact without friction */
    pd_state t = *s;
    double g[NMARGIN];
    if (!pd_phase_project_velocity(&p, &t) ||
        !(margin(&p, &t, PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size), g) > 0.0))
        return 0;
    /* The projection is an inelastic impulse: admitted only when it takes
     * next to nothing, else every entry would damp the part like the
     * microcollisions the phase replaces (tolerances.h). */
    double lost = kinetic(b, s) - kinetic(b, &t);
    if (lost > PD_TOL_PHASE_ENTRY_REL * b->mass * sc->gravity * b->size)
        return 0;
    *s = t;
    return 1;
}

pd_status pd_contact_phase(const pd_sim_model *m, pd_ode *ode, const pd_scene *sc, pd_state *s,
                           const int *contacts, int nc, double t_max, double *t_used)
{
    const pd_body *b = m->body;
    pd_phase p;
    phase_of(&p, m, sc, s, contacts, nc);
    double slip_min = PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    /* First trial step a hundredth of the part's time unit: contact motion
     * changes on that unit; the controller grows it (at most 10x a step). */
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
         * crossed, aimed 1% short so the retry lands before the event
         * (regula falsi from the step's start, which the margins being
         * smooth makes converge in a few retries), and a hundredth of the
         * step at least, so a margin that is not smooth still shrinks it
         * geometrically; a failed step or a model failure halves it. When the crossing is within the event
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
