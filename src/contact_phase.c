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
#include "posedrop/tolerances.h"
#include "quat.h"
#include "vec3.h"

enum { X = 0, V = 3, Q = 6, W = 10, NY = 13 };

enum { SLIDE, STICK };

typedef struct {
    const pd_body *b;
    int nc;
    int v[2];        /* contact vertices */
    int mode[2];     /* SLIDE or STICK */
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

/* Solves the n x n system A x = b in place by Gaussian elimination with
 * partial pivoting; 0 if a pivot falls below PD_TOL_PHASE_PIVOT_REL of the
 * matrix's largest entry. */
static int solve_dense(int n, double A[6][6], double b[6])
{
    double scale = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            scale = fmax(scale, fabs(A[i][j]));
    for (int k = 0; k < n; k++) {
        int piv = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i][k]) > fabs(A[piv][k]))
                piv = i;
        if (!(fabs(A[piv][k]) > PD_TOL_PHASE_PIVOT_REL * scale))
            return 0;
        for (int j = 0; j < n; j++) {
            double t = A[k][j];
            A[k][j] = A[piv][j];
            A[piv][j] = t;
        }
        double t = b[k];
        b[k] = b[piv];
        b[piv] = t;
        for (int i = k + 1; i < n; i++) {
            double f = A[i][k] / A[k][k];
            for (int j = k; j < n; j++)
                A[i][j] -= f * A[k][j];
            b[i] -= f * b[k];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        for (int j = i + 1; j < n; j++)
            b[i] -= A[i][j] * b[j];
        b[i] /= A[i][i];
    }
    return 1;
}

/* The constrained directions of the contacts, body frame: a sliding contact
 * constrains its normal n (one row); a sticking one n, t1, t2 (three). The
 * unknowns follow the same layout, a sliding contact's along its force
 * direction dir[i] (n - mu s for forces, n for the impulses of
 * project_velocity). Returns the count. */
typedef struct {
    int n;
    int c[6];       /* contact of each row / unknown */
    pd_vec3 row[6]; /* constrained direction */
    pd_vec3 col[6]; /* direction of the unknown force */
} layout;

static void make_layout(const phase *p, pd_vec3 up, const pd_vec3 dir[2], layout *L)
{
    pd_vec3 t1 = v3_unit(v3_cross(up, fabs(up.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0)));
    pd_vec3 t2 = v3_cross(up, t1);
    L->n = 0;
    for (int i = 0; i < p->nc; i++) {
        if (p->mode[i] == SLIDE) {
            L->c[L->n] = i, L->row[L->n] = up, L->col[L->n] = dir[i], L->n++;
        } else {
            const pd_vec3 ax[3] = {up, t1, t2};
            for (int k = 0; k < 3; k++)
                L->c[L->n] = i, L->row[L->n] = ax[k], L->col[L->n] = ax[k], L->n++;
        }
    }
}

/* The unknowns x of layout L such that each constrained component of the
 * contacts' acceleration (or velocity) change K x equals rhs. For two
 * sticking contacts K is singular (the squeeze along the edge moves
 * nothing): the least-norm solution is taken, from the normal equations with
 * the squeeze set to zero by one more row. 0 if singular. */
static int solve_layout(const phase *p, const layout *L, const double rhs[6], double x[6])
{
    const pd_body *b = p->b;
    double K[7][6], r[7];
    for (int i = 0; i < L->n; i++) {
        pd_vec3 ri = b->verts[p->v[L->c[i]]];
        for (int j = 0; j < L->n; j++) {
            pd_vec3 rj = b->verts[p->v[L->c[j]]];
            pd_vec3 t = v3_cross(rj, L->col[j]);
            pd_vec3 al = v3(b->inv_moment[0] * t.x, b->inv_moment[1] * t.y, b->inv_moment[2] * t.z);
            K[i][j] = v3_dot(L->row[i], v3_add(v3_scale(L->col[j], 1.0 / b->mass), v3_cross(al, ri)));
        }
        r[i] = rhs[i];
    }
    double A[6][6];
    if (!(p->nc == 2 && p->mode[0] == STICK && p->mode[1] == STICK)) {
        for (int i = 0; i < L->n; i++) {
            for (int j = 0; j < L->n; j++)
                A[i][j] = K[i][j];
            x[i] = r[i];
        }
        return solve_dense(L->n, A, x);
    }
    /* Squeeze row: (f0 - f1) . e = 0, e the edge, scaled like K's rows. */
    pd_vec3 e = v3_unit(v3_sub(b->verts[p->v[1]], b->verts[p->v[0]]));
    for (int j = 0; j < 6; j++)
        K[6][j] = (j < 3 ? 1.0 : -1.0) * v3_dot(L->col[j], e) / b->mass;
    r[6] = 0.0;
    for (int i = 0; i < 6; i++) {
        x[i] = 0.0;
        for (int k = 0; k < 7; k++)
            x[i] += K[k][i] * r[k];
        for (int j = 0; j < 6; j++) {
            A[i][j] = 0.0;
            for (int k = 0; k < 7; k++)
                A[i][j] += K[k][i] * K[k][j];
        }
    }
    return solve_dense(6, A, x);
}

/* Per contact of state s: its velocity (world) and the sliding force
 * direction n - mu s (body frame; n alone if it does not slide). */
static void contact_kinematics(const phase *p, const pd_state *s, pd_vec3 vel[2], pd_vec3 dir[2])
{
    for (int j = 0; j < p->nc; j++) {
        pd_vec3 r = p->b->verts[p->v[j]];
        vel[j] = v3_add(s->v, quat_rotate(s->q, v3_cross(s->w, r)));
        double sl = hypot(vel[j].x, vel[j].y);
        pd_vec3 d = sl > 0.0 ? v3(-p->mu * vel[j].x / sl, -p->mu * vel[j].y / sl, 1.0) : v3(0, 0, 1);
        dir[j] = quat_rotate_inv(s->q, d);
    }
}

/* The contact forces of state s and the accelerations they give (SI): acc
 * of the com (world), wdot (body). Per contact: normal force fn, its margin
 * inside the friction cone (sticking: mu fn - |ft|; sliding: infinite) and
 * slip speed. Returns 0, or 1 where the model does not hold (a sliding
 * contact with no slip to give friction a direction, a singular system). */
static int forces(const phase *p, const pd_state *s, pd_vec3 *acc, pd_vec3 *wdot, double fn[2],
                  double cone[2], double slip[2])
{
    const pd_body *b = p->b;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    pd_vec3 w = s->w;
    pd_vec3 Iw = v3(b->moment[0] * w.x, b->moment[1] * w.y, b->moment[2] * w.z);
    pd_vec3 gyro = v3_cross(w, Iw);
    pd_vec3 a0 = v3(-b->inv_moment[0] * gyro.x, -b->inv_moment[1] * gyro.y, -b->inv_moment[2] * gyro.z);
    pd_vec3 vel[2], dir[2];
    contact_kinematics(p, s, vel, dir);
    for (int j = 0; j < p->nc; j++) {
        slip[j] = hypot(vel[j].x, vel[j].y);
        if (p->mode[j] == SLIDE && !(slip[j] > 0.0))
            return 1;
    }
    layout L;
    make_layout(p, up, dir, &L);
    /* Free acceleration of each contact (body frame components): gravity,
     * the gyroscopic angular acceleration and the centripetal term. */
    double rhs[6] = {0}, x[6];
    pd_vec3 gb = v3_scale(up, -p->g);
    for (int i = 0; i < L.n; i++) {
        pd_vec3 r = b->verts[p->v[L.c[i]]];
        pd_vec3 af = v3_add(gb, v3_add(v3_cross(a0, r), v3_cross(w, v3_cross(w, r))));
        rhs[i] = -v3_dot(L.row[i], af);
    }
    if (!solve_layout(p, &L, rhs, x))
        return 1;
    pd_vec3 F = v3(0.0, 0.0, 0.0), f[2] = {v3(0, 0, 0), v3(0, 0, 0)};
    for (int k = 0; k < L.n; k++)
        f[L.c[k]] = v3_add(f[L.c[k]], v3_scale(L.col[k], x[k]));
    *wdot = a0;
    for (int j = 0; j < p->nc; j++) {
        pd_vec3 t = v3_cross(b->verts[p->v[j]], f[j]);
        *wdot = v3_add(*wdot, v3(b->inv_moment[0] * t.x, b->inv_moment[1] * t.y, b->inv_moment[2] * t.z));
        F = v3_add(F, f[j]);
        fn[j] = v3_dot(f[j], up);
        double ft = v3_norm(v3_sub(f[j], v3_scale(up, fn[j])));
        cone[j] = p->mode[j] == STICK ? p->mu * fn[j] - ft : HUGE_VAL;
    }
    *acc = v3_add(quat_rotate(s->q, v3_scale(F, 1.0 / b->mass)), v3(0.0, 0.0, -p->g));
    return 0;
}

static int phase_rhs(double tau, const double y[], double dydt[], void *user)
{
    (void)tau;
    const phase *p = user;
    pd_state s = from_y(p, y);
    pd_vec3 acc, wdot;
    double fn[2], cone[2], slip[2];
    if (forces(p, &s, &acc, &wdot, fn, cone, slip))
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

/* How far s is from the phase's end, in the part's units: per contact its
 * normal force and, sticking, its force's distance inside the friction cone
 * (per unit weight) or, sliding, its slip above slip_min (per sqrt(g L));
 * and the height of the lowest other vertex above the contacts (per L); into
 * g[NMARGIN]. Each is a smooth function of the state, so an event inside a
 * step is found by the secant method on the one that crossed. Returns the
 * smallest (positive while the phase may go on), or -1 where the model
 * fails. */
enum { NMARGIN = 5 };

static double margin(const phase *p, const pd_state *s, double slip_min, double g[NMARGIN])
{
    pd_vec3 acc, wdot;
    double fn[2], cone[2], slip[2];
    for (int k = 0; k < NMARGIN; k++)
        g[k] = HUGE_VAL;
    if (forces(p, s, &acc, &wdot, fn, cone, slip))
        return -1.0;
    const pd_body *b = p->b;
    double V0 = p->L / p->T, mg = b->mass * p->g;
    for (int i = 0; i < p->nc; i++) {
        g[i] = fn[i] / mg;
        g[2 + i] = p->mode[i] == STICK ? cone[i] / mg : (slip[i] - slip_min) / V0;
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

/* Brings the constrained velocity components to zero (a sliding contact's
 * normal speed, a sticking contact's whole velocity) by the impulses along
 * them that change the kinetic energy least: an orthogonal projection in the
 * mass metric, so the energy cannot rise whatever the impulses' signs.
 * Microcollisions leave resting contacts chattering at up to the rest speed;
 * a phase needs them exactly in contact. 0 if the system is singular. */
static int project_velocity(const phase *p, pd_state *s)
{
    const pd_body *b = p->b;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    const pd_vec3 dir[2] = {up, up};
    layout L;
    make_layout(p, up, dir, &L);
    double rhs[6] = {0}, x[6];
    for (int i = 0; i < L.n; i++) {
        pd_vec3 r = b->verts[p->v[L.c[i]]];
        pd_vec3 vb = v3_add(quat_rotate_inv(s->q, s->v), v3_cross(s->w, r));
        rhs[i] = -v3_dot(L.row[i], vb);
    }
    if (!solve_layout(p, &L, rhs, x))
        return 0;
    for (int k = 0; k < L.n; k++) {
        pd_vec3 P = v3_scale(L.col[k], x[k]);
        s->v = v3_add(s->v, quat_rotate(s->q, v3_scale(P, 1.0 / b->mass)));
        pd_vec3 t = v3_cross(b->verts[p->v[L.c[k]]], P);
        s->w = v3_add(s->w, v3(b->inv_moment[0] * t.x, b->inv_moment[1] * t.y, b->inv_moment[2] * t.z));
    }
    return 1;
}

static double kinetic(const pd_body *b, const pd_state *s)
{
    return 0.5 * b->mass * v3_dot(s->v, s->v) +
           0.5 * (b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                  b->moment[2] * s->w.z * s->w.z);
}

/* The phase for contacts[0..nc) of state s, each contact sliding if its
 * slip is above twice the end threshold, else sticking. */
static phase phase_of(const pd_sim_model *m, const pd_scene *sc, const pd_state *s,
                      const int *contacts, int nc)
{
    const pd_body *b = m->body;
    phase p = {b, nc, {contacts[0], nc > 1 ? contacts[1] : -1}, {SLIDE, SLIDE}, sc->mu,
               sc->gravity, b->size, sqrt(b->size / sc->gravity)};
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(sc->gravity * b->size);
    pd_vec3 vel[2], dir[2];
    contact_kinematics(&p, s, vel, dir);
    for (int i = 0; i < nc; i++)
        p.mode[i] = hypot(vel[i].x, vel[i].y) > slip_start ? SLIDE : STICK;
    return p;
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
    phase p = phase_of(m, sc, s, contacts, nc);
    for (int i = 0; i < nc; i++)
        if (p.mode[i] == STICK && sc->mu == 0.0)
            return 0; /* nothing holds a contact without friction */
    pd_state t = *s;
    double g[NMARGIN];
    if (!project_velocity(&p, &t) ||
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
    phase p = phase_of(m, sc, s, contacts, nc);
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
