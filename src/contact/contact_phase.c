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
 * undetermined, and the system takes the solution without it (least norm;
 * phase_forces.c solves it). A resting contact, both contacts of a
 * resting edge, or the resting end of an edge whose other end slides, whose
 * sticking force would leave the friction cone slide from rest
 * (pd_phase_slide_from_rest, pd_phase_slide_edge_from_rest,
 * pd_phase_slide_end_from_rest):
 * friction along the direction each slip then grows in, until the slip
 * reaches the start threshold, and along the slip from there, in the same
 * phase. A lone contact's slide is refused where another vertex is
 * predicted to land first (lands_first); an edge's is not. It slides from
 * rest only while its sticking force stays outside the cone
 * (else it would stick again). Where no direction is found for one contact
 * (just outside the cone's edge) or the part turns too fast for lands_first
 * to judge, it slips clipped (PD_PHASE_CLIP, phase_forces.h). A sticking
 * contact whose force reaches the cone goes on either way within the phase
 * (slip_onset). An edge one of whose contacts would pull on the floor is
 * the other contact's phase. Sliding friction does negative work and
 * sticking contacts none, so the energy can only fall. Two sticking
 * contacts are a rotation about their edge, one angle, run in closed form
 * (contact_pivot.c: a pendulum, the time an elliptic integral, the events
 * functions of the angle alone), the commonest phase of a part rolling on a
 * rim. Every other phase's ODE is integrated by gsl_adapter's Cash-Karp pair (rkck) in units of the
 * part (length L, time sqrt(L/g)); the phase ends, handing the state back
 * to the microcollisions, just before any of:
 *  - a normal force reaching zero (a contact lifts off),
 *  - a sliding contact's slip falling below PD_TOL_PHASE_SLIP_REL sqrt(g L)
 *    (one sliding from rest: reaching twice that ends nothing, its friction
 *    turns to its slip),
 *  - a sticking contact's force leaving the friction cone (it starts to slip),
 *  - another vertex reaching the floor (an impact),
 *  - the system becoming singular (as in Painleve's paradox),
 * located from smooth models of the margin that crossed (a force's cubic,
 * a vertex height's quintic, time_to_event), to within
 * PD_TOL_PHASE_EVENT_REL sqrt(L/g) before it; and it ends the drop when the
 * energy test decides it. */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "contact/contact_phase.h"
#include "contact/contact_pivot.h"
#include "settle/settle.h"
#include "base/gsl_adapter.h"
#include "contact/phase_forces.h"
#include "contact/contact_tol.h"
#include "base/quat.h"
#include "base/vec3.h"

enum { X = 0, V = 3, Q = 6, W = 10, NY = 13 };

/* rkck rather than rk8pd: a phase is a few steps between events, and about
 * half of them (the step past an event, the landings short of it) are cut
 * by the event, not by the error; there 5 right-hand sides a step beat 12.
 * Measured at PD_TOL_PHASE_ODE_REL (300 drops, seed 3), instructions per
 * phase, rk8pd -> rkck: cube 108k -> 76k, box 112k -> 79k, coin 107k -> 62k. */
pd_ode *pd_contact_phase_ode_alloc(void)
{
    return pd_contact_phase_ode_alloc_tol(1.0);
}

pd_ode *pd_contact_phase_ode_alloc_tol(double tol_scale)
{
    double tol = tol_scale * PD_TOL_PHASE_ODE_REL;
    return pd_ode_alloc_method(PD_ODE_RKCK, NY, tol, tol);
}

pd_ode *pd_contact_phase_spin_ode_alloc_tol(double tol_scale)
{
    double tol = tol_scale * PD_TOL_PHASE_ODE_REL;
    return pd_ode_alloc_method(PD_ODE_RK8PD, NY, tol, tol);
}

int pd_contact_phase_spins_fast(const pd_body *b, double g, const pd_state *s)
{
    return v3_norm(s->w) * sqrt(b->size / g) > PD_PHASE_SPIN_FAST;
}

/* The same pair and tolerance for a pivot's angle (rad) and rate (per
 * sqrt(L/g)): an error of e in the angle moves the part by e L at most,
 * as an error of e in the full motion's position (per L) does. */
pd_ode *pd_contact_pivot_ode_alloc(void)
{
    return pd_contact_pivot_ode_alloc_tol(1.0);
}

pd_ode *pd_contact_pivot_ode_alloc_tol(double tol_scale)
{
    double tol = tol_scale * PD_TOL_PHASE_ODE_REL;
    return pd_ode_alloc_method(PD_ODE_RKCK, 2, tol, tol);
}

/* What a phase integrates: the full motion, y = (x, v, q, w) in the part's
 * units, or a pivot's (contact_pivot.h), y = (angle, rate in the part's
 * units); n unknowns. With the units' factors, for the right-hand side to
 * multiply by (a division costs it a dozen multiplications' time). */
typedef struct {
    const pd_phase *p;
    const pd_pivot *pv; /* NULL: the full motion */
    int n;
    double V0, inv_T, T2, acc_unit; /* sqrt(g L), 1/T, T^2, T^2/L */
} motion;

static motion motion_of(const pd_phase *p)
{
    motion mo = {p, NULL, NY, p->L / p->T, 1.0 / p->T, p->T * p->T, p->T * p->T / p->L};
    return mo;
}

static void to_y(const motion *mo, const pd_state *s, double y[NY])
{
    const pd_phase *p = mo->p;
    if (mo->pv) {
        y[0] = 0.0, y[1] = pd_pivot_rate_of(mo->pv, s) * p->T;
        return;
    }
    double V0 = p->L / p->T;
    const double c[NY] = {s->x.x / p->L, s->x.y / p->L, s->x.z / p->L, s->v.x / V0, s->v.y / V0,
                          s->v.z / V0, s->q.w, s->q.x, s->q.y, s->q.z, s->w.x * p->T,
                          s->w.y * p->T, s->w.z * p->T};
    memcpy(y, c, sizeof c);
}

static pd_state from_y(const motion *mo, const double y[NY])
{
    double L = mo->p->L, V0 = mo->V0, k = mo->inv_T;
    pd_state s;
    s.x = v3(y[X] * L, y[X + 1] * L, y[X + 2] * L);
    s.v = v3(y[V] * V0, y[V + 1] * V0, y[V + 2] * V0);
    /* y's q drifts off the unit sphere within a step by its error alone. */
    double n = 1.0 / sqrt(y[Q] * y[Q] + y[Q + 1] * y[Q + 1] + y[Q + 2] * y[Q + 2] +
                          y[Q + 3] * y[Q + 3]);
    s.q = quat(y[Q] * n, y[Q + 1] * n, y[Q + 2] * n, y[Q + 3] * n);
    s.w = v3(y[W] * k, y[W + 1] * k, y[W + 2] * k);
    return s;
}

/* The time derivative of y (part units), with the state and forces it
 * comes from. 1 where the model fails. */
static int derivs(const motion *mo, const double y[NY], pd_state *s, pd_phase_forces *F,
                  double dydt[NY])
{
    const pd_phase *p = mo->p;
    double T = p->T;
    if (mo->pv) {
        double alpha = pd_pivot_state(mo->pv, y[0], y[1] / T, s, F);
        dydt[0] = y[1], dydt[1] = alpha * T * T;
        return 0;
    }
    *s = from_y(mo, y);
    if (pd_phase_forces_of(p, s, F))
        return 1;
    double a = mo->acc_unit, T2 = mo->T2;
    pd_quat q = quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]);
    pd_quat dq = quat_mul(q, quat(0.0, y[W], y[W + 1], y[W + 2]));
    const double d[NY] = {y[V], y[V + 1], y[V + 2], F->acc.x * a, F->acc.y * a,
                          F->acc.z * a, 0.5 * dq.w, 0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z,
                          F->wdot.x * T2, F->wdot.y * T2, F->wdot.z * T2};
    memcpy(dydt, d, sizeof d);
    return 0;
}

/* A pivot's right-hand side needs neither the state nor the forces. */
static int phase_rhs(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const motion *mo = user;
    if (mo->pv) {
        double T = mo->p->T;
        dydt[0] = y[1], dydt[1] = pd_pivot_accel(mo->pv, y[0]) * T * T;
        return 0;
    }
    pd_state s;
    pd_phase_forces F;
    return derivs(mo, y, &s, &F, dydt);
}

/* How far s is from the phase's end, in the part's units: per contact its
 * normal force and, sticking, its force's distance inside the friction cone
 * (per unit weight) or, sliding, its slip above slip_min (per sqrt(g L));
 * with a drilling contact, the spin about the normal (SPIN, below); and the
 * height of the lowest other vertex above the floor, the lowest contact
 * (*floor_v) (per L); into g[NMARGIN], from s's forces F. Each is a
 * smooth function of the state (the height, per vertex), so an event inside
 * a step is found from a smooth model of the one that crossed. Returns the
 * smallest (positive while the phase may go on). */
enum { SPIN = 4, HEIGHT = 5, NMARGIN = 6 };

/* The height of body vertex w above body vertex v at s (up: the world's up
 * in the body frame), per L. */
static double height_of(const pd_phase *p, pd_vec3 up, int v, int w)
{
    return v3_dot(up, v3_sub(p->b->verts[w], p->b->verts[v])) / p->L;
}

/* 1 if body vertex w is one of the phase's contacts. The next vertex to
 * touch is looked for among the contacts' edge neighbours less these
 * (margins, time_to_event, predicted_event). */
static int is_contact(const pd_phase *p, int w)
{
    return w == p->v[0] || (p->nc == 2 && w == p->v[1]);
}

static double margins(const pd_phase *p, const pd_state *s, const pd_phase_forces *F,
                      double slip_min, double g[NMARGIN], int *floor_v, pd_vec3 *up_out)
{
    const pd_body *b = p->b;
    double V0 = p->L / p->T, mg = b->mass * p->g;
    for (int k = 0; k < NMARGIN; k++)
        g[k] = HUGE_VAL;
    for (int i = 0; i < p->nc; i++) {
        g[i] = F->fn[i] / mg;
        g[2 + i] = p->mode[i] != PD_PHASE_SLIDE ? F->cone[i] / mg
                   : p->from_rest[i]                ? (2.0 * slip_min - F->slip[i]) / V0
                                                    : (F->slip[i] - slip_min) / V0;
    }
    /* A lone contact slipping from rest (so the second contact's slot is
     * free): also while its sticking force lies outside the cone (sliding
     * from rest), or until its slip reaches the speed a slide starts at
     * (clipped). */
    if (p->nc == 1 && p->from_rest[0])
        g[3] = F->cone[0] / mg;
    else if (p->mode[0] == PD_PHASE_CLIP)
        g[3] = (2.0 * slip_min - F->slip[0]) / V0;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    *up_out = up;
    /* With a drilling contact: the spin about the normal, in the direction
     * the phase began with, per 1 / sqrt(L/g); the phase ends where it
     * reaches zero. */
    double drill = p->drill[0] != 0.0 ? p->drill[0] : p->drill[1];
    if (drill != 0.0)
        g[SPIN] = (drill > 0.0 ? 1.0 : -1.0) * v3_dot(s->w, up) * p->T;
    /* The contacts' own height defines the floor. */
    *floor_v = p->v[0];
    if (p->nc == 2 && v3_dot(up, b->verts[p->v[1]]) < v3_dot(up, b->verts[p->v[0]]))
        *floor_v = p->v[1];
    /* The next vertex to touch: while the contacts are the lowest, the
     * lowest other vertex is an edge neighbour of one of them (on a convex
     * polytope the vertices below any height are connected), and the margin
     * is continuous, so it crosses zero before any other vertex could. */
    for (int i = 0; i < p->nc; i++)
        for (int k = b->adj_start[p->v[i]]; k < b->adj_start[p->v[i] + 1]; k++) {
            int w = b->adj[k];
            if (is_contact(p, w))
                continue;
            double h = height_of(p, up, *floor_v, w);
            if (h < g[HEIGHT]) /* as fmin, NaN aside, without its call */
                g[HEIGHT] = h;
        }
    double least = HUGE_VAL;
    for (int k = 0; k < NMARGIN; k++)
        least = fmin(least, g[k]);
    return least;
}

/* A point of the phase: its time, y and state, y's derivative, the angular
 * acceleration (body frame), the floor's contact, its margins and smallest
 * margin (-1 where the model fails), once asked for (rated), the force
 * margins' rates of change and, once asked for (bit k of jets_set), the
 * height jet of the contacts' k-th other neighbour (height_jet_of): the
 * models of two successive steps share their middle point, and a point's
 * jets were computed for the step before. */
enum { NJETS = 64 };
typedef struct {
    double tau, y[NY], dydt[NY];
    pd_state s;
    pd_vec3 wdot, up, up_w; /* up: the world's, body frame; up_w = up x w */
    int floor_v;
    double g[NMARGIN], dg[HEIGHT], least;
    int rated;
    uint64_t jets_set;
    double jet[NJETS][3];
} point;

static void point_at(const motion *mo, double slip_min, double tau, const double y[NY], point *a)
{
    pd_phase_forces F;
    a->tau = tau, a->rated = 0, a->jets_set = 0;
    memcpy(a->y, y, sizeof a->y); /* fixed size, inlined; a pivot's y is a full buffer too */
    for (int k = 0; k < NMARGIN; k++)
        a->g[k] = HUGE_VAL;
    if (derivs(mo, y, &a->s, &F, a->dydt)) {
        a->least = -1.0;
        return;
    }
    a->wdot = F.wdot;
    a->least = margins(mo->p, &a->s, &F, slip_min, a->g, &a->floor_v, &a->up);
    a->up_w = v3_cross(a->up, a->s.w);
}

/* The force margins' rates of change at a, by a forward difference along
 * the flow (PD_TOL_PHASE_RATE_STEP); NaN where unknown (the model fails
 * there, or the margin is infinite). */
static void rate(const motion *mo, double slip_min, point *a)
{
    if (a->rated)
        return;
    double e = PD_TOL_PHASE_RATE_STEP, y[NY];
    for (int i = 0; i < mo->n; i++)
        y[i] = a->y[i] + e * a->dydt[i];
    point b;
    point_at(mo, slip_min, a->tau + e, y, &b);
    for (int k = 0; k < HEIGHT; k++)
        a->dg[k] = b.least > -1.0 && isfinite(a->g[k]) && isfinite(b.g[k]) ? (b.g[k] - a->g[k]) / e
                                                                           : (double)NAN;
    a->rated = 1;
}

/* Vertex w's height at a (margins) and its first two derivatives per unit
 * time sqrt(L/g), exactly, from the state and the angular acceleration: in
 * the body frame d/dt up . r = up . (w x r), as up turns by up x w, and
 * d2/dt2 up . r = (up x w) . (w x r) + up . (wdot x r), r the vertex's arm
 * from the floor's contact. */
static void height_jet(const pd_phase *p, const point *a, int w, double jet[3])
{
    const pd_body *b = p->b;
    pd_vec3 r = v3_sub(b->verts[w], b->verts[a->floor_v]);
    jet[0] = height_of(p, a->up, a->floor_v, w);
    pd_vec3 wr = v3_cross(a->s.w, r);
    jet[1] = v3_dot(a->up, wr) * p->T / p->L;
    jet[2] = (v3_dot(a->up_w, wr) + v3_dot(a->up, v3_cross(a->wdot, r))) * p->T * p->T / p->L;
}

/* height_jet of vertex w, the contacts' k-th neighbour other than
 * themselves (in margins' order), at a: kept in a from its first use. */
static const double *height_jet_of(const pd_phase *p, point *a, int k, int w, double tmp[3])
{
    if (k >= NJETS) {
        height_jet(p, a, w, tmp);
        return tmp;
    }
    if (!(a->jets_set >> k & 1)) {
        height_jet(p, a, w, a->jet[k]);
        a->jets_set |= (uint64_t)1 << k;
    }
    return a->jet[k];
}

/* The polynomial c[0] + c[1] s + ... + c[5] s^5, and its slope, at s. */
enum { NCOEF = 6 };

static double poly(const double c[NCOEF], double s)
{
    double f = c[NCOEF - 1];
    for (int k = NCOEF - 2; k >= 0; k--)
        f = f * s + c[k];
    return f;
}

static double poly_slope(const double c[NCOEF], double s)
{
    double f = (NCOEF - 1) * c[NCOEF - 1];
    for (int k = NCOEF - 2; k >= 1; k--)
        f = f * s + k * c[k];
    return f;
}

/* The polynomial's first zero in (s0, s1], given its values g0 > 0 at s0
 * and g1 <= 0 at s1 (passed as computed where they came from, not from the
 * coefficients, which may round them across zero): the first of 16 cells
 * where it reaches zero, then that cell narrowed to 2^-36 of itself, ~1e-12
 * of the step: far below the event tolerance for any step the phase takes. The
 * narrowing is Newton's method from the secant's point, kept inside the
 * cell (bisecting where it would leave it), and once its steps are below
 * the width, two points half the width either side close the cell: about 7
 * evaluations (values and slopes) where bisection took 36 (measured on
 * random cubics, the result within the width of bisection's). */
static double poly_zero(const double c[NCOEF], double s0, double s1, double g0, double g1)
{
    enum { CELLS = 16, MAX_NARROWINGS = 60 };
    const double width = 0x1p-36 / CELLS * (s1 - s0);
    double lo = s0, hi = s1, flo = g0, fhi = g1;
    for (int i = 1; i < CELLS; i++) {
        double s = s0 + (s1 - s0) * i / CELLS, f = poly(c, s);
        if (f <= 0.0) {
            hi = s, fhi = f;
            break;
        }
        lo = s, flo = f;
    }
    double x = lo + flo / (flo - fhi) * (hi - lo);
    for (int i = 0; i < MAX_NARROWINGS && hi - lo > width; i++) {
        if (!(x > lo && x < hi))
            x = 0.5 * (lo + hi);
        double f = poly(c, x);
        if (f > 0.0)
            lo = x;
        else
            hi = x;
        double step = f / poly_slope(c, x);
        if (fabs(step) < 0.25 * width) {
            const double side[2] = {x - 0.5 * width, x + 0.5 * width};
            for (int k = 0; k < 2; k++)
                if (side[k] > lo && side[k] < hi) {
                    if (poly(c, side[k]) > 0.0)
                        lo = side[k];
                    else
                        hi = side[k];
                }
            x = 0.5 * (lo + hi);
        } else {
            x -= step;
        }
    }
    return lo;
}

/* The quintic in s (0 at a, 1 at b) of vertex w's height into c[0..NCOEF),
 * matching its value, slope and curvature at both ends (height_jet); the
 * height at b into c[NCOEF]; returns the height at a. */
static double height_model(const pd_phase *p, point *a, point *b, int k, int w,
                           double c[NCOEF + 1])
{
    double len = b->tau - a->tau, ta[3], tb[3];
    const double *ja = height_jet_of(p, a, k, w, ta), *jb = height_jet_of(p, b, k, w, tb);
    /* g0 + m0 s + c0/2 s^2 plus the cubic, quartic and quintic terms that
     * take up the misfits e0, e1, e2 of that quadratic's value, slope and
     * curvature at 1. */
    double m0 = len * ja[1], c0 = len * len * ja[2];
    double e0 = jb[0] - (ja[0] + m0 + 0.5 * c0), e1 = len * jb[1] - (m0 + c0);
    double e2 = len * len * jb[2] - c0;
    const double cc[NCOEF + 1] = {ja[0],
                                  m0,
                                  0.5 * c0,
                                  10.0 * e0 - 4.0 * e1 + 0.5 * e2,
                                  -15.0 * e0 + 7.0 * e1 - e2,
                                  6.0 * e0 - 3.0 * e1 + 0.5 * e2,
                                  jb[0]};
    memcpy(c, cc, sizeof cc);
    return ja[0];
}

/* The time from a to the first event before b (where some margin is not
 * positive). A force margin's model is the cubic Hermite interpolant of its
 * values and rates at both ends (a secant where a rate is unknown): its
 * error falls as the fourth power of the interval. The height's is the
 * quintic one of the values and two derivatives of each vertex below the
 * floor at b, its error falls as the sixth power; per vertex, not of the
 * lowest one's margin, whose derivatives jump where another vertex becomes
 * the lowest, and whose model then missed the event by enough to take a
 * step or more again (on the cube 33 phases in 83 did). Measured on the
 * median-band drops, steps: cube 429 -> 379 in 83 phases, 1x2x3 box
 * 365 -> 332 in 65, coin 1582 -> 1492 in 334; every height event now
 * located by one retry past the step that crossed it (the coin's 8 phases
 * that take two end at a force margin). */
static double time_to_event(const motion *mo, double slip_min, point *a, point *b)
{
    const pd_phase *p = mo->p;
    const pd_body *bd = p->b;
    double len = b->tau - a->tau, frac = 1.0;
    for (int k = 0; k < HEIGHT; k++) {
        if (!(b->g[k] <= 0.0))
            continue;
        rate(mo, slip_min, a);
        rate(mo, slip_min, b);
        double g0 = a->g[k], g1 = b->g[k], m0 = len * a->dg[k], m1 = len * b->dg[k];
        if (!isfinite(m0) || !isfinite(m1))
            m0 = m1 = g1 - g0;
        const double c[NCOEF] = {g0, m0, 3.0 * (g1 - g0) - 2.0 * m0 - m1, 2.0 * (g0 - g1) + m0 + m1,
                                 0.0, 0.0};
        frac = fmin(frac, poly_zero(c, 0.0, 1.0, g0, g1));
    }
    if (!(b->g[HEIGHT] <= 0.0))
        return len * frac;
    int n = 0;
    for (int i = 0; i < p->nc; i++)
        for (int k = bd->adj_start[p->v[i]]; k < bd->adj_start[p->v[i] + 1]; k++) {
            int w = bd->adj[k];
            if (is_contact(p, w))
                continue;
            if (!(height_of(p, b->up, b->floor_v, w) <= 0.0)) {
                n++;
                continue;
            }
            double c[NCOEF + 1], g0 = height_model(p, a, b, n++, w, c);
            frac = fmin(frac, poly_zero(c, 0.0, 1.0, g0, c[NCOEF]));
        }
    return len * frac;
}

/* The time from b to the first height event within horizon after it,
 * predicted by extrapolating each vertex's quintic through a and b (a
 * neighbour of the contacts, as in margins); INFINITY if none. It only aims
 * steps: each one's end is still checked (margins), and an event missed is
 * found as before, from the step past it. Where it ends the phase (the
 * event predicted within the tolerance), it extrapolates by at most that
 * tolerance beyond b, which the quintic matches to the same order as
 * within. */
static double predicted_event(const pd_phase *p, point *a, point *b, double horizon)
{
    const pd_body *bd = p->b;
    double len = b->tau - a->tau, s1 = 1.0 + horizon / len, best = INFINITY;
    int n = 0;
    for (int i = 0; i < p->nc; i++)
        for (int k = bd->adj_start[p->v[i]]; k < bd->adj_start[p->v[i] + 1]; k++) {
            int w = bd->adj[k];
            if (is_contact(p, w))
                continue;
            double c[NCOEF + 1];
            height_model(p, a, b, n++, w, c);
            double g1 = poly(c, s1);
            if (!(g1 <= 0.0))
                continue;
            best = fmin(best, len * (poly_zero(c, 1.0, s1, c[NCOEF], g1) - 1.0));
        }
    return best;
}

/* The contacts and modes of the phase for contacts[0..nc) of state s,
 * each contact sliding if its slip is above twice the end threshold, else
 * sticking; no force solve set up yet (pd_phase_map). */
static void phase_of(pd_phase *p, const pd_settle *st, const pd_scene *sc, const pd_state *s,
                     const int *contacts, int nc)
{
    const pd_body *b = st->body;
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    pd_phase_modes(p, b, sc->gravity, sc->mu, s, contacts, nc, slip_start);
    /* A sticking contact of a phase that can spin about the floor's normal
     * (one contact, or an edge not pivoting): Coulomb friction over its
     * patch, uniform pressure on a disc of radius a, gives a couple of at
     * most (2/3) mu N a against the spin (docs/contact.md, "Drilling
     * friction"). The phase ends where the spin does (margins). A sliding
     * contact's friction goes to its slip: left out there. */
    int spins = nc == 1 || p->mode[0] != p->mode[1];
    double wn = v3_dot(s->w, quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0)));
    double k = 2.0 / 3.0 * sc->mu * st->patch;
    for (int i = 0; i < nc && spins && k > 0.0; i++)
        if (p->mode[i] == PD_PHASE_STICK)
            p->drill[i] = wn > 0.0 ? k : wn < 0.0 ? -k : 0.0;
}

/* 1 if a vertex other than the contacts of phase p at s, coming down at its
 * present rate (height_jet's first order), lands within time dt (s). Then
 * a contact sliding from rest would hand over to microcollisions before its
 * slip reached the start threshold (a part rolling over a rim of close
 * vertices, parts/cap.off, does nearly every time), leaving a small slip
 * that makes the landing's microcollision a slow sliding integration where,
 * stuck, it would have been cheap. First order, not second: the second's
 * term is mostly the part toppling from rest, which speeds its slip too,
 * so it refused slides that reached the threshold first more often than not
 * (docs/performance.md). */
static int lands_first(const pd_phase *p, const pd_state *s, double slip_min, double dt)
{
    const pd_body *b = p->b;
    motion mo = motion_of(p);
    double y[NY], tau = dt / p->T;
    point a;
    to_y(&mo, s, y);
    point_at(&mo, slip_min, 0.0, y, &a);
    if (!(a.least > -1.0))
        return 0;
    for (int i = 0; i < p->nc; i++)
        for (int k = b->adj_start[p->v[i]]; k < b->adj_start[p->v[i] + 1]; k++) {
            int w = b->adj[k];
            if (is_contact(p, w))
                continue;
            double j[3];
            height_jet(p, &a, w, j);
            if (j[0] + j[1] * tau <= 0.0)
                return 1;
        }
    return 0;
}

int pd_contact_phase_start(const pd_settle *st, const pd_scene *sc, pd_state *s,
                           const int *contacts, int nc, pd_phase *phase)
{
    if (nc < 1 || nc > 2)
        return 0;
    const pd_body *b = st->body;
    double lost_max = PD_TOL_PHASE_ENTRY_REL * b->mass * sc->gravity * b->size;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0)); /* body frame, as r and w */
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = b->verts[contacts[i]];
        double vn = s->v.z + v3_dot(up, v3_cross(s->w, r));
        if (fabs(vn) > st->v_rest)
            return 0; /* a flight or an impact, not chatter */
        /* The entry's projection (below) stops at least this contact's
         * normal speed, and a projection onto fewer constraints loses less
         * energy: stopping vn alone by the impulse along the normal loses
         * vn^2 / 2K, K = 1/m + (r x n) . I^-1 (r x n). So this bound
         * refuses early, with no solve set up, most of the starts the
         * energy test below would (100 drops, seed 3: 490 of 507 on the
         * coin, 103 of 103 on the cube, 104 of 105 on the 1x2x3 box); it
         * never refuses one that test admits, round-off at the limit
         * aside. */
        pd_vec3 c = v3_cross(r, up);
        double K = 1.0 / b->mass + c.x * c.x * b->inv_moment[0] + c.y * c.y * b->inv_moment[1] +
                   c.z * c.z * b->inv_moment[2];
        if (0.5 * vn * vn / K > lost_max)
            return 0;
    }
    pd_phase p;
    phase_of(&p, st, sc, s, contacts, nc);
    for (int i = 0; i < nc; i++)
        if (p.mode[i] == PD_PHASE_STICK && sc->mu == 0.0)
            return 0; /* nothing holds a contact without friction */
    pd_state t = *s;
    double g[NMARGIN], slip_min = PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    pd_phase_forces F;
    pd_pivot pv;
    int floor_v, pivot = pd_pivot_init(&pv, &p, s);
    double w = 0.0;
    if (pivot) {
        /* Two sticking contacts: the projection and the forces in closed
         * form (contact_pivot.h), no solve set up; a full phase sets it up
         * if it needs it (pd_contact_phase). */
        w = pd_pivot_rate_of(&pv, s);
        t.v = v3_scale(pv.e_u, w);
        t.w = v3_scale(pv.eb, w);
    } else {
        pd_phase_map(&p); /* after the refusals that need no solve */
        if (!pd_phase_project_velocity(&p, &t))
            return 0;
    }
    /* The projection is an inelastic impulse: admitted only when it takes
     * next to nothing, else every entry would damp the part like the
     * microcollisions the phase replaces (tolerances.h). Tested before
     * the forces, which cost more; the bound above has taken most of
     * what it would refuse. */
    double lost = pd_body_kinetic(b, s) - pd_body_kinetic(b, &t);
    if (lost > lost_max)
        return 0;
    if (pivot) {
        pd_state u;
        pd_pivot_state(&pv, 0.0, w, &u, &F);
    } else if (pd_phase_forces_of(&p, &t, &F)) {
        return 0;
    }
    double least = margins(&p, &t, &F, slip_min, g, &floor_v, &up), accel;
    int stuck_out = !(least > 0.0) && !pivot && nc == 1 && p.mode[0] == PD_PHASE_STICK &&
                    F.cone[0] <= 0.0;
    pd_phase q = p;
    if (stuck_out && pd_phase_slide_from_rest(&p, &t, &accel)) {
        /* One contact that cannot stick: it slides from rest, and the
         * phase follows it (microcollisions would stop its slip at each
         * one, every rest step, until it slipped faster than friction
         * can stop in one), unless another vertex lands first. */
        if (pd_phase_forces_of(&p, &t, &F))
            return 0;
        least = margins(&p, &t, &F, slip_min, g, &floor_v, &up);
        double horizon = 2.0 * slip_min / accel;
        if (least > 0.0 && lands_first(&p, &t, slip_min, horizon)) {
            /* Believed where the part turns little over the horizon; where
             * it turns more, a vertex's height is not its first order (a
             * top's corners bob at its spin) and the slip goes on clipped. */
            if (v3_norm(t.w) * horizon < PD_PHASE_LANDS_TURN)
                return 0;
            p = q, least = 0.0;
        } else {
            stuck_out = 0;
        }
    } else if (!(least > 0.0) && pivot && fmin(F.cone[0], F.cone[1]) <= 0.0 &&
               pd_phase_slide_edge_from_rest(&p, &t, &accel)) {
        /* An edge that cannot stick: both its contacts slide from rest,
         * as one contact's would above, but also where another vertex
         * lands first. Refused there (lands_first), the edge went to
         * microcollisions, each stopping the slip its rest step had grown,
         * until the landing; unlike a lone contact's (parts/cap.off), the
         * slip the phase leaves does not make the landing's microcollision
         * dearer (docs/performance.md, "Contact phases: an edge's slide
         * from rest"). */
        if (pd_phase_forces_of(&p, &t, &F))
            return 0;
        least = margins(&p, &t, &F, slip_min, g, &floor_v, &up);
    }
    if (stuck_out) {
        /* Outside the cone, but so near its edge that the slide from rest
         * has no direction found, or turning too fast for lands_first to
         * judge the slide (a top precessing on a corner, the excess tiny
         * and the slide slow, which mostly ends with the sticking force
         * back inside the cone): it starts to slip all the same, clipped
         * (phase_forces.h), the slide's limit at the cone's edge. */
        p.mode[0] = PD_PHASE_CLIP;
        if (pd_phase_forces_of(&p, &t, &F))
            return 0;
        least = margins(&p, &t, &F, slip_min, g, &floor_v, &up);
    }
    for (int i = 0; i < nc && nc == 2 && !pivot && !(least > 0.0); i++) {
        /* An edge one of whose contacts slides while the other's sticking
         * force lies outside the cone (its margin alone not positive): that
         * one slides from rest too, as a lone contact's would. */
        int other_ok = 1;
        for (int k = 0; k < NMARGIN; k++)
            other_ok = other_ok && (k == 2 + i || g[k] > 0.0);
        if (!other_ok || p.mode[i] != PD_PHASE_STICK)
            continue;
        pd_phase slid = p;
        if (!pd_phase_slide_end_from_rest(&slid, &t, i, &accel) || pd_phase_forces_of(&slid, &t, &F))
            continue;
        p = slid;
        least = margins(&p, &t, &F, slip_min, g, &floor_v, &up);
    }
    if (!(least > 0.0)) {
        /* An edge one of whose contacts would pull on the floor (its normal
         * force not positive) lifts off there: the other's phase, alone,
         * is the edge's. */
        for (int i = 0; i < nc && nc == 2; i++)
            if (!(g[i] > 0.0) && g[1 - i] > 0.0)
                return pd_contact_phase_start(st, sc, s, contacts + 1 - i, 1, phase);
        return 0;
    }
    /* The phase goes on with the modes the projection was for: taken
     * afresh from t, a contact that slid above the start threshold and
     * slips less after the projection would count as sticking, and its
     * force would push it along at that slip, doing work. */
    *s = t;
    *phase = p;
    return 1;
}

/* Where the phase would end at a: a contact sliding from rest whose slip
 * has reached the start threshold (its margin the least) slides on as any
 * other, its friction along its own slip from here, and a is evaluated
 * again for that. 1 if the phase goes on. */
static int slides_on(const motion *mo, pd_phase *p, double slip_min, point *a)
{
    for (int i = 0; i < p->nc; i++)
        if (p->from_rest[i] && a->g[2 + i] <= a->least) {
            double y[NY];
            memcpy(y, a->y, sizeof y);
            p->from_rest[i] = 0;
            point_at(mo, slip_min, a->tau, y, a);
            return a->least > 0.0;
        }
    return 0;
}

/* At a located event within tol of cur, the crossing of end's margins:
 * where the one margin crossed is a lone sticking contact's friction cone,
 * the contact starts to slide from rest there, within the phase: cur steps
 * past the crossing (dt to it, then half the tolerance) and the contact
 * goes on sliding from rest (pd_phase_slide_from_rest) or, where that
 * finds no direction (mostly: so near the cone's edge), clipped
 * (phase_forces.h). Ending the phase there instead handed a contact that
 * grazes the cone back and forth between phases that each stopped short
 * of the crossing and microcollisions that each put it back (60,000 of
 * them in 0.01 s on a 0.1 mm top). 1 if cur is the slide's new start, with
 * positive margins; 0 (cur and p as they were) to end the phase. */
static int slip_onset(const motion *mo, pd_ode *ode, pd_phase *p, double slip_min, double dt,
                      double tol, point *cur, const point *end)
{
    if (!(p->nc == 1 && p->mode[0] == PD_PHASE_STICK && end->least > -1.0 && end->g[2] <= 0.0))
        return 0;
    for (int k = 0; k < NMARGIN; k++)
        if (k != 2 && !(end->g[k] > 0.0))
            return 0;
    double y[NY], tau = cur->tau, h = dt + 0.5 * tol, accel;
    memcpy(y, cur->y, sizeof y);
    if (pd_ode_step_from(ode, phase_rhs, (void *)mo, &tau, cur->tau + h, &h, y, cur->dydt) !=
        PD_OK)
        return 0;
    pd_phase q = *p;
    point at;
    point_at(mo, slip_min, tau, y, &at); /* for its state */
    if (!pd_phase_slide_from_rest(p, &at.s, &accel))
        p->mode[0] = PD_PHASE_CLIP; /* so near the cone's edge, its limit */
    point_at(mo, slip_min, tau, y, &at);
    if (!(at.least > 0.0)) {
        *p = q;
        return 0;
    }
    *cur = at;
    return 1;
}

pd_status pd_contact_phase(const pd_settle *settle, pd_ode *ode, pd_ode *pivot_ode,
                           const pd_scene *sc, const pd_phase *phase, pd_state *s, double t_max,
                           double *t_used)
{
    const pd_body *b = settle->body;
    pd_phase p = *phase;
    pd_pivot pv;
    motion mo = motion_of(&p); /* the right-hand side takes it as void * */
    if (pivot_ode && pd_pivot_init(&pv, &p, s))
        mo.pv = &pv, mo.n = 2, ode = pivot_ode;
    else if (!p.mapped)
        pd_phase_map(&p);
    double slip_min = PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    const double tol = PD_TOL_PHASE_EVENT_REL;
    if (mo.pv) {
        /* A pivot in closed form (contact_pivot.h): to half the event
         * tolerance before its event, as the steps below aim. The energy
         * test is not asked on the way: the energy is constant, so a drop
         * it would decide there is decided where the phase hands over too
         * (the basin it is in then holds the same energy), and the drop
         * asks it first thing. */
        double a, w, t;
        if (pd_pivot_run(&pv, pd_pivot_rate_of(&pv, s), t_max, 0.5 * tol * p.T, &a, &w, &t)) {
            pd_phase_forces F;
            if (t > 0.0)
                pd_pivot_state(&pv, a, w, s, &F);
            *t_used = t;
            return PD_OK;
        }
    }
    /* First trial step a twentieth of the part's time unit: contact motion
     * changes on that unit. Measured (300 drops, seed 3), right-hand sides
     * per phase for a first step of 0.01, 0.02, 0.05, 0.1: cube 44, 43, 41,
     * 45; box 45, 43, 43, 46; coin 30, 28, 28, 27 (larger ones cost rejected
     * steps). The controller grows it, at most 10x a step. */
    double tau_max = t_max / p.T, h = 0.05, target = INFINITY;
    double y[NY];
    int hint = 0, pose, bracket = 0;
    /* The phase's last two points (prev NULL until there are two), a
     * step's end, and the nearest end past an event: four buffers, passed
     * round rather than copied. */
    point buf[4], *prev = NULL, *cur = &buf[0], *next = &buf[1], *end = &buf[2];
    point *spare = &buf[3];
    to_y(&mo, s, y);
    point_at(&mo, slip_min, 0.0, y, cur);
    for (int step = 0; step < PD_PHASE_MAX_STEPS && cur->tau < tau_max && cur->least > 0.0;
         step++) {
        double tau = cur->tau, h_try = h;
        memcpy(y, cur->y, sizeof y);
        double t1 = fmin(tau_max, fmin(target, tau + 10.0 * h));
        pd_status st = pd_ode_step_from(ode, phase_rhs, &mo, &tau, t1, &h, y, cur->dydt);
        double len = st == PD_OK ? tau - cur->tau : fmin(t1 - cur->tau, h_try);
        next->least = -1.0;
        if (st == PD_OK) {
            if (!mo.pv) {
                /* Keep the quaternion on the unit sphere between steps. */
                pd_quat q = quat_normalize(quat(y[Q], y[Q + 1], y[Q + 2], y[Q + 3]));
                y[Q] = q.w, y[Q + 1] = q.x, y[Q + 2] = q.y, y[Q + 3] = q.z;
            }
            point_at(&mo, slip_min, tau, y, next);
        }
        if (next->least > 0.0) {
            point *old = prev ? prev : spare;
            prev = cur, cur = next, next = old;
            *s = cur->s;
            target = INFINITY;
            /* Landed short of a known event: aim again, from here. Else
             * look ahead for a vertex coming down within the next step
             * (predicted_event) and aim at it: the step lands within the
             * tolerance of it, or close enough that the next one does, and
             * the step past it and the retry from before it are saved.
             * Ahead at most 1.3 suggested steps (further, aiming costs
             * steps the controller rejects) and two of the intervals the
             * model comes from (further, its extrapolation misses by more
             * than the steps it would save). Measured on the median-band
             * drops, steps and instructions in phases, not looking ahead:
             * cube 379, 2.89M; box 332, 2.52M; coin 1492, 11.49M; looking
             * 1 step or 1 interval ahead: 325, 2.67M; 289, 2.37M; 1296,
             * 10.69M; 1 step or 2 intervals: 317, 2.62M; 287, 2.35M; 1283,
             * 10.61M; 1.3 or 2: 309, 2.58M; 281, 2.33M; 1253, 10.49M; 1.6
             * or 2: 309, 2.66M; 280, 2.36M; 1251, 10.64M. */
            const double ahead_steps = 1.3, ahead_intervals = 2.0;
            double dt = bracket ? time_to_event(&mo, slip_min, cur, end)
                                : predicted_event(&p, prev, cur,
                                                  fmin(ahead_steps * h,
                                                       ahead_intervals * (cur->tau - prev->tau)));
            if (dt <= tol) {
                if (slides_on(&mo, &p, slip_min, cur))
                    continue;
                if (!bracket || !slip_onset(&mo, ode, &p, slip_min, dt, tol, cur, end))
                    break;
                *s = cur->s;
                bracket = 0, target = INFINITY;
                continue;
            }
            if (isfinite(dt)) {
                target = cur->tau + dt - 0.5 * tol;
                h = target - cur->tau;
            }
            if (pd_settle_decided(settle, s, sc->gravity, &hint, &pose) > 0)
                break;
            continue;
        }
        if (st != PD_OK && st != PD_ERR_INTERNAL && st != PD_ERR_NO_CONVERGENCE)
            return st;
        /* An event inside the step: back to its start, and step again to
         * half the event tolerance short of the event's estimate, which a
         * smooth model (time_to_event) makes accurate enough that this
         * retry mostly lands within the tolerance; landing short, the next
         * step aims again, landing past, the retry does. A failed step or a
         * model failure halves the step. When the event is within the
         * tolerance, hand over. */
        double dt = 0.5 * len;
        int modelled = next->least > -1.0;
        if (modelled) {
            point *old = end;
            end = next, next = old;
            bracket = 1;
            dt = time_to_event(&mo, slip_min, cur, end);
        }
        if (dt <= tol) {
            if (!slides_on(&mo, &p, slip_min, cur) &&
                !(modelled && slip_onset(&mo, ode, &p, slip_min, dt, tol, cur, end)))
                break;
            *s = cur->s;
            bracket = 0, target = INFINITY;
            continue;
        }
        target = cur->tau + (modelled ? dt - 0.5 * tol : dt);
        h = target - cur->tau;
    }
    *t_used = cur->tau * p.T;
    return PD_OK;
}
