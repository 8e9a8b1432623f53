/* phase_forces.c: a contact phase's forces (see phase_forces.h; the model
 * is described in contact_phase.c).
 *
 * The right-hand side of the phase's ODE solves the force system six times
 * per step, so the common layouts skip the general assembly: one sliding
 * contact, nine phases in ten, is a 1 x 1 system written out (slide_one; so
 * is its velocity projection), and contacts that all stick (a pivot, a
 * rotation about an edge) have a constant system in the body frame, so
 * their solution is a constant map computed once per phase. Contacts that
 * all slide have one unknown each (1 x 1 or 2 x 2); one of each (rare)
 * takes the general layout. Every system is assembled from the contacts'
 * constant response matrices. */
#include <math.h>
#include <string.h>
#include "base/mat3.h"
#include "contact/phase_forces.h"
#include "contact/contact_tol.h"
#include "base/illinois.h"
#include "base/quat.h"
#include "base/vec3.h"

enum { SLIDE = PD_PHASE_SLIDE, STICK = PD_PHASE_STICK, CLIP = PD_PHASE_CLIP };

/* Solves A X = B for m right-hand sides in place: Ab holds [A | B] (n rows,
 * n + m columns) and B's columns become X's, by Gaussian elimination with
 * partial pivoting; 0 if a pivot falls below PD_TOL_PHASE_PIVOT_REL of A's
 * largest entry. */
enum { AUG = 12 };

static int solve_dense(int n, int m, double Ab[6][AUG])
{
    double scale = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            if (fabs(Ab[i][j]) > scale) /* as fmax, NaN aside, without its call */
                scale = fabs(Ab[i][j]);
    for (int k = 0; k < n; k++) {
        int piv = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(Ab[i][k]) > fabs(Ab[piv][k]))
                piv = i;
        if (!(fabs(Ab[piv][k]) > PD_TOL_PHASE_PIVOT_REL * scale))
            return 0;
        for (int j = 0; j < n + m; j++) {
            double t = Ab[k][j];
            Ab[k][j] = Ab[piv][j];
            Ab[piv][j] = t;
        }
        for (int i = k + 1; i < n; i++) {
            double f = Ab[i][k] / Ab[k][k];
            for (int j = k; j < n + m; j++)
                Ab[i][j] -= f * Ab[k][j];
        }
    }
    for (int c = n; c < n + m; c++)
        for (int i = n - 1; i >= 0; i--) {
            for (int j = i + 1; j < n; j++)
                Ab[i][c] -= Ab[i][j] * Ab[j][c];
            Ab[i][c] /= Ab[i][i];
        }
    return 1;
}

/* solve_dense for n = 1 or 2 and one right-hand side, written out: the
 * same pivoting, test and arithmetic without the loops, for the sliding
 * contacts that solve it at every right-hand side. A 1 x 1 system is
 * singular only at 0 (the test is relative to the entry itself). */
static int solve_small(int n, double A[6][AUG])
{
    if (n == 1) {
        if (!(fabs(A[0][0]) > 0.0))
            return 0;
        A[0][1] /= A[0][0];
        return 1;
    }
    double scale = 0.0;
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            if (fabs(A[i][j]) > scale)
                scale = fabs(A[i][j]);
    if (fabs(A[1][0]) > fabs(A[0][0]))
        for (int j = 0; j < 3; j++) {
            double t = A[0][j];
            A[0][j] = A[1][j];
            A[1][j] = t;
        }
    if (!(fabs(A[0][0]) > PD_TOL_PHASE_PIVOT_REL * scale))
        return 0;
    double f = A[1][0] / A[0][0];
    A[1][1] -= f * A[0][1];
    A[1][2] -= f * A[0][2];
    if (!(fabs(A[1][1]) > PD_TOL_PHASE_PIVOT_REL * scale))
        return 0;
    A[1][2] /= A[1][1];
    A[0][2] = (A[0][2] - A[0][1] * A[1][2]) / A[0][0];
    return 1;
}

/* The constrained directions of the contacts, body frame: a sliding contact
 * constrains its normal n (one row); a sticking one its whole acceleration,
 * along axes[0..3) (three rows). The unknowns follow the same layout, a
 * sliding contact's along its force direction dir[i] (n - mu s for forces,
 * n for the impulses of the velocity projection). */
typedef struct {
    int n;
    int c[6];       /* contact of each row / unknown */
    pd_vec3 row[6]; /* constrained direction */
    pd_vec3 col[6]; /* direction of the unknown force */
} layout;

static void make_layout(const pd_phase *p, pd_vec3 up, const pd_vec3 dir[2], const pd_vec3 axes[3],
                        layout *L)
{
    L->n = 0;
    for (int i = 0; i < p->nc; i++) {
        if (p->mode[i] == SLIDE) {
            L->c[L->n] = i, L->row[L->n] = up, L->col[L->n] = dir[i], L->n++;
        } else {
            for (int k = 0; k < 3; k++)
                L->c[L->n] = i, L->row[L->n] = axes[k], L->col[L->n] = axes[k], L->n++;
        }
    }
}

static const pd_vec3 body_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

/* The unknowns X of layout L such that each constrained component of the
 * contacts' acceleration (or velocity) change K X equals B, for m
 * right-hand sides (columns of B; X's replace them). For two sticking
 * contacts K is singular (the squeeze along the edge moves nothing): the
 * least-norm solution is taken, from the normal equations with the squeeze
 * set to zero by one more row. 0 if singular. */
static int solve_layout(const pd_phase *p, const layout *L, pd_vec3 up, int drilling, int m,
                        double B[6][6])
{
    int n = L->n;
    double K[7][6], Ab[6][AUG];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            K[i][j] = v3_dot(L->row[i], m3_vec(CONST_M3(p->M[L->c[i]][L->c[j]]), L->col[j]));
    if (drilling) {
        /* A drilling contact's couple, -drill (up . f) up, turns the part:
         * contact i's acceleration gains -drill (up . f) (I^-1 up) x r_i,
         * linear in the unknowns of the drilling contact. */
        pd_vec3 Iu = pd_body_inv_inertia(p->b, up);
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double d = p->drill[L->c[j]];
                if (d != 0.0)
                    K[i][j] -= d * v3_dot(up, L->col[j]) *
                               v3_dot(L->row[i], v3_cross(Iu, p->r[L->c[i]]));
            }
    }
    if (!(p->nc == 2 && p->mode[0] == STICK && p->mode[1] == STICK)) {
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++)
                Ab[i][j] = K[i][j];
            for (int c = 0; c < m; c++)
                Ab[i][n + c] = B[i][c];
        }
    } else {
        /* Squeeze row: (f0 - f1) . e = 0, e the edge, scaled like K's rows;
         * its right-hand side is 0. */
        pd_vec3 e = v3_unit(v3_sub(p->r[1], p->r[0]));
        for (int j = 0; j < 6; j++)
            K[6][j] = (j < 3 ? 1.0 : -1.0) * v3_dot(L->col[j], e) / p->b->mass;
        for (int i = 0; i < 6; i++) {
            for (int j = 0; j < 6; j++) {
                Ab[i][j] = 0.0;
                for (int k = 0; k < 7; k++)
                    Ab[i][j] += K[k][i] * K[k][j];
            }
            for (int c = 0; c < m; c++) {
                Ab[i][6 + c] = 0.0;
                for (int k = 0; k < 6; k++)
                    Ab[i][6 + c] += K[k][i] * B[k][c];
            }
        }
    }
    if (!solve_dense(n, m, Ab))
        return 0;
    for (int i = 0; i < n; i++)
        for (int c = 0; c < m; c++)
            B[i][c] = Ab[i][n + c];
    return 1;
}

/* No contact slides: the constrained rows are the body axes (a clipped
 * contact's sticking force is solved first, then clipped). */
static int all_stick(const pd_phase *p)
{
    return p->mode[0] != SLIDE && (p->nc == 1 || p->mode[1] != SLIDE);
}

/* A lone clipped contact (phase_forces.h): its sticking force fs (body
 * frame) becomes lambda d, d = n + mu t the cone's edge along fs's
 * tangential direction t, lambda holding the normal acceleration at zero
 * with the drilling couple, -drill lambda n, turning the part as it does
 * the sticking force; *excess: how far fs lies outside the cone. 1 where
 * fs has no tangential direction. */
static int clip_force(const pd_phase *p, pd_vec3 up, pd_vec3 af, pd_vec3 *f, double *excess)
{
    double fn = v3_dot(*f, up);
    pd_vec3 ft = v3_sub(*f, v3_scale(up, fn));
    double t = v3_norm(ft);
    if (!(t > 0.0))
        return 1;
    *excess = t - p->mu * fn;
    pd_vec3 d = v3_add(up, v3_scale(ft, p->mu / t));
    pd_vec3 u = v3_cross(pd_body_inv_inertia(p->b, up), p->r[0]);
    double k = v3_dot(up, m3_vec(CONST_M3(p->M[0][0]), d)) - p->drill[0] * v3_dot(up, u);
    if (!(fabs(k) > 0.0))
        return 1;
    *f = v3_scale(d, -v3_dot(up, af) / k);
    return 0;
}

/* The velocity of contact j of state s (world), R the body-to-world matrix;
 * *wr = w x r, body frame. */
static inline pd_vec3 contact_velocity(const pd_phase *p, const double R[3][3], const pd_state *s, int j,
                                pd_vec3 *wr)
{
    *wr = v3_cross(s->w, p->r[j]);
    return v3_add(s->v, m3_vec(R, *wr));
}

void pd_phase_modes(pd_phase *p, const pd_body *b, double g, double mu, const pd_state *s,
                    const int *contacts, int nc, double slip_start)
{
    memset(p, 0, sizeof *p);
    p->b = b, p->nc = nc, p->mu = mu, p->g = g, p->L = b->size, p->T = sqrt(b->size / g);
    double R[3][3];
    quat_to_matrix(s->q, R);
    for (int i = 0; i < nc; i++) {
        p->v[i] = contacts[i];
        p->r[i] = b->verts[contacts[i]];
        pd_vec3 wr, vel = contact_velocity(p, CONST_M3(R), s, i, &wr);
        p->mode[i] = sqrt(vel.x * vel.x + vel.y * vel.y) > slip_start ? SLIDE : STICK;
    }
    if (nc == 1)
        p->v[1] = -1;
}

/* The contacts' responses M, and mapped set, for phases that need no P
 * (some contact slides). */
static void map_responses(pd_phase *p)
{
    const pd_body *b = p->b;
    int nc = p->nc;
    p->mapped = 1;
    /* Column k of M[i][j]: contact i's acceleration by a unit force along
     * body axis k at contact j, f / m + (I^-1 (r_j x f)) x r_i. */
    for (int i = 0; i < nc; i++)
        for (int j = 0; j < nc; j++)
            for (int k = 0; k < 3; k++) {
                pd_vec3 f = body_axes[k];
                pd_vec3 a = v3_add(v3_scale(f, 1.0 / b->mass),
                                   v3_cross(pd_body_inv_inertia(b, v3_cross(p->r[j], f)), p->r[i]));
                p->M[i][j][0][k] = a.x, p->M[i][j][1][k] = a.y, p->M[i][j][2][k] = a.z;
            }
}

void pd_phase_map(pd_phase *p)
{
    map_responses(p);
    if (!all_stick(p))
        return;
    /* Every contact sticks: the rows and unknowns are the body axes, K is
     * constant, and the solution is linear in the right-hand side: column k
     * of P is the solution for the k-th unit right-hand side. */
    layout L;
    const pd_vec3 unused[2] = {v3(0, 0, 1), v3(0, 0, 1)};
    make_layout(p, v3(0, 0, 1), unused, body_axes, &L);
    for (int i = 0; i < L.n; i++)
        for (int k = 0; k < L.n; k++)
            p->P[i][k] = i == k;
    p->singular = !solve_layout(p, &L, v3(0, 0, 1), 0, L.n, p->P);
}

void pd_phase_init(pd_phase *p, const pd_body *b, double g, double mu, const pd_state *s,
                   const int *contacts, int nc, double slip_start)
{
    pd_phase_modes(p, b, g, mu, s, contacts, nc, slip_start);
    pd_phase_map(p);
}

/* mu times the world direction of sliding contact j's slip, from its
 * velocity vel (world) of tangential speed sl, or its start direction while
 * it slides from rest; 0 where it has no direction. */
static int friction_dir(const pd_phase *p, int j, pd_vec3 vel, double sl, double *cx, double *cy)
{
    if (p->from_rest[j]) {
        *cx = p->mu * p->t0[j].x, *cy = p->mu * p->t0[j].y;
        return 1;
    }
    if (!(sl > 0.0))
        return 0;
    *cx = p->mu * vel.x / sl, *cy = p->mu * vel.y / sl;
    return 1;
}

/* Contact 0 of a lone contact sliding from rest, af its free acceleration
 * (body frame): how far its sticking force would lie outside the friction
 * cone, |ft| - mu fn of the sticking solution (P, set while it stuck). Where
 * this is no longer positive the contact would stick again, and its slide
 * from rest is over (contact_phase.c): a top precessing on a corner needs
 * a little more friction than the cone gives for a moment of each turn,
 * and slides with friction fixed along the start direction would go on
 * past it, pushing the contact back along its slip. */
static double stick_excess(const pd_phase *p, pd_vec3 up, pd_vec3 af)
{
    pd_vec3 f = v3(-(p->P[0][0] * af.x + p->P[0][1] * af.y + p->P[0][2] * af.z),
                   -(p->P[1][0] * af.x + p->P[1][1] * af.y + p->P[1][2] * af.z),
                   -(p->P[2][0] * af.x + p->P[2][1] * af.y + p->P[2][2] * af.z));
    double fn = v3_dot(f, up);
    return v3_norm(v3_sub(f, v3_scale(up, fn))) - p->mu * fn;
}

/* One sliding contact, the commonest phase (314 of the coin's 334
 * median-band phases), written out: the force is lambda d, d = n - mu s the
 * sliding direction (body frame), lambda from the one row n . (a_free +
 * M d lambda) = 0; its normal component is lambda itself, and in the world
 * d is (-mu s_x, -mu s_y, 1), so the centre's acceleration needs no
 * rotation. */
static int slide_one(const pd_phase *p, const double R[3][3], const pd_state *s, pd_vec3 a0,
                     pd_phase_forces *out)
{
    const pd_body *b = p->b;
    pd_vec3 up = v3(R[2][0], R[2][1], R[2][2]), w = s->w;
    pd_vec3 wr, vel = contact_velocity(p, R, s, 0, &wr);
    double sl = sqrt(vel.x * vel.x + vel.y * vel.y), cx, cy;
    if (!friction_dir(p, 0, vel, sl, &cx, &cy))
        return 1;
    pd_vec3 af = v3_add(v3_scale(up, -p->g), v3_add(v3_cross(a0, p->r[0]), v3_cross(w, wr)));
    pd_vec3 d = v3(up.x - cx * R[0][0] - cy * R[1][0], up.y - cx * R[0][1] - cy * R[1][1],
                   up.z - cx * R[0][2] - cy * R[1][2]);
    double k = v3_dot(up, m3_vec(CONST_M3(p->M[0][0]), d));
    if (!(fabs(k) > 0.0))
        return 1;
    double lambda = -v3_dot(up, af) / k, lm = lambda / b->mass;
    out->wdot = v3_add(a0, pd_body_inv_inertia(b, v3_cross(p->r[0], v3_scale(d, lambda))));
    out->acc = v3(-cx * lm, -cy * lm, lm - p->g);
    out->fn[0] = lambda;
    out->cone[0] = p->from_rest[0] ? stick_excess(p, up, af) : HUGE_VAL;
    out->slip[0] = sl;
    return 0;
}

static int forces(const pd_phase *p, const pd_state *s, int general, pd_phase_forces *out)
{
    const pd_body *b = p->b;
    if (!p->mapped)
        return 1;
    double R[3][3];
    quat_to_matrix(s->q, R);
    pd_vec3 up = v3(R[2][0], R[2][1], R[2][2]);
    pd_vec3 w = s->w;
    pd_vec3 Iw = v3(b->moment[0] * w.x, b->moment[1] * w.y, b->moment[2] * w.z);
    pd_vec3 a0 = v3_neg(pd_body_inv_inertia(b, v3_cross(w, Iw)));
    if (!general && p->nc == 1 && p->mode[0] == SLIDE)
        return slide_one(p, CONST_M3(R), s, a0, out);
    /* Per contact: its slip, its sliding force direction n - mu s (body
     * frame), and its free acceleration (body frame): gravity, the
     * gyroscopic angular acceleration and the centripetal term. */
    pd_vec3 dir[2], af[2];
    for (int j = 0; j < p->nc; j++) {
        pd_vec3 wr, vel = contact_velocity(p, CONST_M3(R), s, j, &wr);
        double sl = sqrt(vel.x * vel.x + vel.y * vel.y);
        out->slip[j] = sl;
        af[j] = v3_add(v3_scale(up, -p->g), v3_add(v3_cross(a0, p->r[j]), v3_cross(w, wr)));
        dir[j] = up;
        if (p->mode[j] == SLIDE) {
            /* R^T (-mu s_x, -mu s_y, 1): rows 0 and 1 of R are the world's
             * x and y axes in the body frame. */
            double cx, cy;
            if (!friction_dir(p, j, vel, sl, &cx, &cy))
                return 1;
            dir[j] = v3(up.x - cx * R[0][0] - cy * R[1][0], up.y - cx * R[0][1] - cy * R[1][1],
                        up.z - cx * R[0][2] - cy * R[1][2]);
        }
    }
    pd_vec3 f[2] = {v3(0, 0, 0), v3(0, 0, 0)};
    if (!general && all_stick(p)) {
        if (p->singular)
            return 1;
        double rhs[6] = {0}, x[6];
        int n = 3 * p->nc;
        for (int j = 0; j < p->nc; j++)
            rhs[3 * j] = -af[j].x, rhs[3 * j + 1] = -af[j].y, rhs[3 * j + 2] = -af[j].z;
        for (int i = 0; i < n; i++) {
            x[i] = 0.0;
            for (int k = 0; k < n; k++)
                x[i] += p->P[i][k] * rhs[k];
        }
        for (int j = 0; j < p->nc; j++)
            f[j] = v3(x[3 * j], x[3 * j + 1], x[3 * j + 2]);
        if (p->drill[0] != 0.0) {
            /* One contact sticking and drilling: the couple -drill fn up
             * turns the part, so the contact's acceleration is M f + af -
             * drill (up . f) u with u = (I^-1 up) x r, and holding it at
             * zero takes (M - drill u up^T) f = -af: P's solution, the
             * rank-one change added (Sherman and Morrison). */
            pd_vec3 u = v3_cross(pd_body_inv_inertia(b, up), p->r[0]);
            pd_vec3 Pu = v3(p->P[0][0] * u.x + p->P[0][1] * u.y + p->P[0][2] * u.z,
                            p->P[1][0] * u.x + p->P[1][1] * u.y + p->P[1][2] * u.z,
                            p->P[2][0] * u.x + p->P[2][1] * u.y + p->P[2][2] * u.z);
            double den = 1.0 - p->drill[0] * v3_dot(up, Pu);
            if (!(fabs(den) > 0.0))
                return 1;
            f[0] = v3_add(f[0], v3_scale(Pu, p->drill[0] * v3_dot(up, f[0]) / den));
        }
    } else if (!general && p->mode[0] == SLIDE && (p->nc == 1 || p->mode[1] == SLIDE)) {
        /* Every contact slides: one unknown per contact, along its force
         * direction, and one row, its normal. */
        int n = p->nc;
        double A[6][AUG];
        for (int i = 0; i < n; i++) {
            for (int j = 0; j < n; j++)
                A[i][j] = v3_dot(up, m3_vec(CONST_M3(p->M[i][j]), dir[j]));
            A[i][n] = -v3_dot(up, af[i]);
        }
        if (!solve_small(n, A))
            return 1;
        for (int j = 0; j < n; j++)
            f[j] = v3_scale(dir[j], A[j][n]);
    } else {
        pd_vec3 axes[3] = {body_axes[0], body_axes[1], body_axes[2]};
        if (general) {
            /* The contact's own tangent axes, as a check that the
             * body axes of the specialised solves lose nothing. */
            axes[0] = up;
            axes[1] = v3_unit(v3_cross(up, fabs(up.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0)));
            axes[2] = v3_cross(up, axes[1]);
        }
        layout L;
        make_layout(p, up, dir, axes, &L);
        double x[6][6];
        for (int i = 0; i < L.n; i++)
            x[i][0] = -v3_dot(L.row[i], af[L.c[i]]);
        if (!solve_layout(p, &L, up, 1, 1, x))
            return 1;
        for (int k = 0; k < L.n; k++)
            f[L.c[k]] = v3_add(f[L.c[k]], v3_scale(L.col[k], x[k][0]));
    }
    double excess = 0.0;
    if (p->mode[0] == CLIP && clip_force(p, up, af[0], &f[0], &excess))
        return 1;
    pd_vec3 F = v3(0.0, 0.0, 0.0);
    out->wdot = a0;
    for (int j = 0; j < p->nc; j++)
        if (p->drill[j] != 0.0)
            out->wdot = v3_add(out->wdot, pd_body_inv_inertia(b, v3_scale(up, -p->drill[j] *
                                                                             v3_dot(up, f[j]))));
    for (int j = 0; j < p->nc; j++) {
        out->wdot = v3_add(out->wdot, pd_body_inv_inertia(b, v3_cross(p->r[j], f[j])));
        F = v3_add(F, f[j]);
        double fn = v3_dot(f[j], up);
        out->fn[j] = fn;
        out->cone[j] = p->mode[j] == STICK ? p->mu * fn - v3_norm(v3_sub(f[j], v3_scale(up, fn)))
                       : p->mode[j] == CLIP ? excess
                       : p->from_rest[j]    ? stick_excess(p, up, af[j])
                                            : HUGE_VAL;
    }
    out->acc = v3_add(m3_vec(CONST_M3(R), v3_scale(F, 1.0 / b->mass)), v3(0.0, 0.0, -p->g));
    return 0;
}

/* The free acceleration of contact i at s (body frame; up, the world's):
 * gravity, the gyroscopic angular acceleration and the centripetal term. */
static pd_vec3 free_accel(const pd_phase *p, const pd_state *s, pd_vec3 up, int i)
{
    const pd_body *b = p->b;
    pd_vec3 w = s->w, wr = v3_cross(w, p->r[i]);
    pd_vec3 Iw = v3(b->moment[0] * w.x, b->moment[1] * w.y, b->moment[2] * w.z);
    pd_vec3 a0 = v3_neg(pd_body_inv_inertia(b, v3_cross(w, Iw)));
    return v3_add(v3_scale(up, -p->g), v3_add(v3_cross(a0, p->r[i]), v3_cross(w, wr)));
}

/* Sliding along the world's horizontal unit direction t = (c, s), contact
 * 0's normal force is A / k and k times its tangential acceleration (world)
 * is affine in (c, s): k a_x = p0 + p1 c + p2 s, k a_y = q0 + q1 c + q2 s
 * (pd_phase_slide_from_rest). Of that, k times the cross product t x a, a
 * quadratic form in (c, s), and k itself. */
typedef struct {
    double k0, k1, k2, p0, p1, p2, q0, q1, q2;
} slide_form;

static double form_cross(const slide_form *f, double c, double s)
{
    return c * (f->q0 + f->q1 * c + f->q2 * s) - s * (f->p0 + f->p1 * c + f->p2 * s);
}

int pd_phase_slide_from_rest(pd_phase *p, const pd_state *s, double *accel)
{
    if (p->nc != 1 || p->mode[0] != STICK || !p->mapped || !(p->mu > 0.0))
        return 0;
    double R[3][3];
    quat_to_matrix(s->q, R);
    pd_vec3 up = v3(R[2][0], R[2][1], R[2][2]), X = v3(R[0][0], R[0][1], R[0][2]);
    pd_vec3 Y = v3(R[1][0], R[1][1], R[1][2]), af = free_accel(p, s, up, 0);
    /* The force is lambda d, d = n - mu t (body frame: up - mu (c X + s Y)),
     * so M d = m0 - mu (c mx + s my), k = up . M d, lambda = A / k with
     * A = -up . af, and k a = k af + A M d. */
    double A = -v3_dot(up, af), mu = p->mu;
    if (!(A > 0.0))
        return 0; /* nothing presses the contact onto the floor */
    const double(*M)[3] = CONST_M3(p->M[0][0]);
    pd_vec3 m0 = m3_vec(M, up), mx = m3_vec(M, X), my = m3_vec(M, Y);
    double xa = v3_dot(X, af), ya = v3_dot(Y, af);
    slide_form f = {v3_dot(up, m0), -mu * v3_dot(up, mx), -mu * v3_dot(up, my), 0, 0, 0, 0, 0, 0};
    f.p0 = f.k0 * xa + A * v3_dot(X, m0);
    f.p1 = f.k1 * xa - A * mu * v3_dot(X, mx);
    f.p2 = f.k2 * xa - A * mu * v3_dot(X, my);
    f.q0 = f.k0 * ya + A * v3_dot(Y, m0);
    f.q1 = f.k1 * ya - A * mu * v3_dot(Y, mx);
    f.q2 = f.k2 * ya - A * mu * v3_dot(Y, my);
    /* The directions the slip keeps are the zeros of t x a with k > 0;
     * those it grows along (t . a > 0) are the ones a slide from rest can
     * take. Bracketed between neighbours of PD_PHASE_START_CELLS directions
     * round the circle (turned by one rotation each, no trigonometry), each
     * then narrowed to round-off. */
    const double step = 2.0 * M_PI / PD_PHASE_START_CELLS, cd = cos(step), sd = sin(step);
    double best = 0.0, bc = 0.0, bs = 0.0, c0 = 1.0, s0 = 0.0, f0 = form_cross(&f, c0, s0);
    for (int k = 1; k <= PD_PHASE_START_CELLS; k++) {
        double c1 = k == PD_PHASE_START_CELLS ? 1.0 : c0 * cd - s0 * sd;
        double s1 = k == PD_PHASE_START_CELLS ? 0.0 : s0 * cd + c0 * sd, f1 = form_cross(&f, c1, s1);
        if ((f0 <= 0.0) != (f1 <= 0.0)) {
            /* Regula falsi along the chord, projected onto the circle
             * (the Illinois variant, which halves the retained end's value
             * when the same end moves twice), to round-off. */
            double lc = c0, ls = s0, flo = f0, hc = c1, hs = s1, fhi = f1;
            int side = 0;
            for (int i = 0; i < 60; i++) { /* a bound: it stalls at round-off first */
                double u = flo / (flo - fhi);
                double mc = lc + u * (hc - lc), ms = ls + u * (hs - ls), n = sqrt(mc * mc + ms * ms);
                mc /= n, ms /= n;
                if ((mc == lc && ms == ls) || (mc == hc && ms == hs))
                    break;
                double fm = form_cross(&f, mc, ms);
                if (fm == 0.0) {
                    lc = mc, ls = ms;
                    break;
                }
                int moved_lo = (fm <= 0.0) == (flo <= 0.0);
                if (moved_lo)
                    lc = mc, ls = ms, flo = fm;
                else
                    hc = mc, hs = ms, fhi = fm;
                pd_illinois_moved(moved_lo, &side, &flo, &fhi);
            }
            double kk = f.k0 + f.k1 * lc + f.k2 * ls;
            double along = (lc * (f.p0 + f.p1 * lc + f.p2 * ls) + ls * (f.q0 + f.q1 * lc + f.q2 * ls)) / kk;
            if (kk > 0.0 && along > best)
                best = along, bc = lc, bs = ls;
        }
        c0 = c1, s0 = s1, f0 = f1;
    }
    if (!(best > 0.0))
        return 0;
    p->mode[0] = SLIDE;
    p->from_rest[0] = 1;
    p->t0[0] = v3(bc, bs, 0.0);
    p->drill[0] = 0.0; /* a sliding contact's friction goes to its slip */
    *accel = best;
    return 1;
}

/* What an edge's slide from rest needs of the state, once: the world's axes
 * in the body frame, each contact's free acceleration, and each response
 * M[k][j] applied to up, X and Y (the force direction d = up - mu (c X +
 * s Y) is their combination). */
typedef struct {
    pd_vec3 up, X, Y, af[2], Mu[2][2], MX[2][2], MY[2][2];
    double mu;
} edge_setup;

/* Both contacts of the edge sliding along the world's horizontal unit
 * directions (c[k], s[k]): each one's cross product of its direction with its
 * tangential acceleration (world) into r[], the slip's acceleration along
 * its direction into along[], its normal force into lambda[]; 0 if the
 * 2 x 2 system of the normal forces is singular. */
static int edge_residual(const edge_setup *e, const double c[2], const double sn[2], double r[2],
                         double along[2], double lambda[2])
{
    pd_vec3 Md[2][2];
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < 2; j++)
            Md[k][j] = v3_sub(e->Mu[k][j], v3_add(v3_scale(e->MX[k][j], e->mu * c[j]),
                                                  v3_scale(e->MY[k][j], e->mu * sn[j])));
    double A[6][AUG];
    for (int i = 0; i < 2; i++) {
        for (int j = 0; j < 2; j++)
            A[i][j] = v3_dot(e->up, Md[i][j]);
        A[i][2] = -v3_dot(e->up, e->af[i]);
    }
    if (!solve_small(2, A))
        return 0;
    lambda[0] = A[0][2], lambda[1] = A[1][2];
    for (int k = 0; k < 2; k++) {
        pd_vec3 a = v3_add(e->af[k], v3_add(v3_scale(Md[k][0], lambda[0]), v3_scale(Md[k][1], lambda[1])));
        double ax = v3_dot(e->X, a), ay = v3_dot(e->Y, a);
        r[k] = c[k] * ay - sn[k] * ax;
        along[k] = c[k] * ax + sn[k] * ay;
    }
    return 1;
}

/* edge_residual at angles th[0], th[1]. */
static int edge_residual_at(const edge_setup *e, const double th[2], double r[2], double along[2],
                            double lambda[2])
{
    const double c[2] = {cos(th[0]), cos(th[1])}, sn[2] = {sin(th[0]), sin(th[1])};
    return edge_residual(e, c, sn, r, along, lambda);
}

/* What edge_residual needs of phase p (responses set) at state s. */
static void edge_setup_of(const pd_phase *p, const pd_state *s, edge_setup *e)
{
    double R[3][3];
    quat_to_matrix(s->q, R);
    e->up = v3(R[2][0], R[2][1], R[2][2]), e->X = v3(R[0][0], R[0][1], R[0][2]);
    e->Y = v3(R[1][0], R[1][1], R[1][2]), e->mu = p->mu;
    for (int k = 0; k < 2; k++) {
        e->af[k] = free_accel(p, s, e->up, k);
        for (int j = 0; j < 2; j++) {
            e->Mu[k][j] = m3_vec(CONST_M3(p->M[k][j]), e->up);
            e->MX[k][j] = m3_vec(CONST_M3(p->M[k][j]), e->X);
            e->MY[k][j] = m3_vec(CONST_M3(p->M[k][j]), e->Y);
        }
    }
}

/* Newton's method on the edge's two directions th[] (its Jacobian by
 * differences), to round-off of the residual (PD_TOL_PHASE_START_RESIDUAL
 * of g); r, along and lambda at the last th. 1 if converged. */
static int edge_newton(const edge_setup *e, double g, double th[2], double r[2], double along[2],
                       double lambda[2])
{
    double h = PD_PHASE_START_DIFF;
    for (int it = 0; it < PD_PHASE_START_NEWTON; it++) {
        if (!edge_residual_at(e, th, r, along, lambda))
            return 0;
        if (fabs(r[0]) + fabs(r[1]) <= PD_TOL_PHASE_START_RESIDUAL * g)
            return 1;
        double J[2][2], rh[2], ah[2], lh[2];
        for (int k = 0; k < 2; k++) {
            double tk[2] = {th[0], th[1]};
            tk[k] += h;
            if (!edge_residual_at(e, tk, rh, ah, lh))
                return 0;
            J[0][k] = (rh[0] - r[0]) / h, J[1][k] = (rh[1] - r[1]) / h;
        }
        double det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
        if (!(fabs(det) > 0.0))
            return 0;
        th[0] -= (J[1][1] * r[0] - J[0][1] * r[1]) / det;
        th[1] -= (J[0][0] * r[1] - J[1][0] * r[0]) / det;
    }
    return 0;
}

/* Both normal forces positive and both slips growing. */
static int edge_admissible(const double lambda[2], const double along[2])
{
    return lambda[0] > 0.0 && lambda[1] > 0.0 && along[0] > 0.0 && along[1] > 0.0;
}

/* q (a copy of the edge's phase) sliding from rest along th[] into *out,
 * the slower slip's acceleration into *accel. */
static void set_edge_slide(pd_phase *q, const double th[2], pd_phase *out, double *accel,
                           const double along[2])
{
    for (int k = 0; k < 2; k++) {
        q->mode[k] = SLIDE;
        q->from_rest[k] = 1;
        q->t0[k] = v3(cos(th[k]), sin(th[k]), 0.0);
        q->drill[k] = 0.0;
    }
    *out = *q;
    *accel = fmin(along[0], along[1]);
}

int pd_phase_slide_edge_from_rest(pd_phase *out, const pd_state *s, double *accel)
{
    const pd_phase *p = out;
    if (p->nc != 2 || p->mode[0] != STICK || p->mode[1] != STICK || !(p->mu > 0.0))
        return 0;
    /* The responses alone: the sticking solve (P) is of no use to the
     * search, nor to the sliding phase it sets. Into a copy, so that p is
     * unchanged where the search fails. */
    pd_phase q = *p;
    if (!q.mapped)
        map_responses(&q);
    p = &q;
    edge_setup e;
    edge_setup_of(p, s, &e);
    /* A first start: each contact's direction of tangential acceleration
     * under its frictionless normal force, which a slide from rest keeps
     * where friction turns neither (an isotropic response: a lone contact
     * with equal moments) and which is near it otherwise; then Newton's
     * method on both directions. Where that does not converge to an
     * admissible pair, the common direction, of PD_PHASE_START_CELLS round
     * the circle (turned by one rotation each), where both slips grow under
     * positive normal forces with the smallest residual, and Newton's method
     * from there. */
    double th[2], r[2], along[2], lambda[2];
    edge_setup e0 = e;
    e0.mu = 0.0;
    const double one[2] = {1.0, 1.0}, zero[2] = {0.0, 0.0};
    if (edge_residual(&e0, one, zero, r, along, lambda)) {
        /* along: each contact's acceleration along X, r: along Y. */
        th[0] = atan2(r[0], along[0]), th[1] = atan2(r[1], along[1]);
        if (edge_newton(&e, p->g, th, r, along, lambda) && edge_admissible(lambda, along)) {
            set_edge_slide(&q, th, out, accel, along);
            return 1;
        }
    }
    const double step = 2.0 * M_PI / PD_PHASE_START_CELLS, cd = cos(step), sd = sin(step);
    double best = HUGE_VAL, c = 1.0, sn = 0.0;
    th[0] = th[1] = 0.0;
    for (int k = 0; k < PD_PHASE_START_CELLS; k++) {
        const double cc[2] = {c, c}, ss[2] = {sn, sn};
        if (edge_residual(&e, cc, ss, r, along, lambda) && edge_admissible(lambda, along) &&
            r[0] * r[0] + r[1] * r[1] < best)
            best = r[0] * r[0] + r[1] * r[1], th[0] = th[1] = step * k;
        double c1 = c * cd - sn * sd;
        sn = sn * cd + c * sd, c = c1;
    }
    if (!(best < HUGE_VAL))
        return 0;
    if (!edge_newton(&e, p->g, th, r, along, lambda) || !edge_admissible(lambda, along))
        return 0;
    set_edge_slide(&q, th, out, accel, along);
    return 1;
}

int pd_phase_slide_end_from_rest(pd_phase *p, const pd_state *s, int i, double *accel)
{
    int j = 1 - i;
    if (p->nc != 2 || i < 0 || i > 1 || p->mode[i] != STICK || p->mode[j] != SLIDE ||
        p->from_rest[j] || !p->mapped || !(p->mu > 0.0))
        return 0;
    /* Contact j's friction is along its slip (world, horizontal). */
    pd_vec3 vj = v3_add(s->v, quat_rotate(s->q, v3_cross(s->w, p->r[j])));
    double sl = sqrt(vj.x * vj.x + vj.y * vj.y);
    if (!(sl > 0.0))
        return 0;
    edge_setup e;
    edge_setup_of(p, s, &e);
    double c[2], sn[2], r[2], along[2], lambda[2];
    c[j] = vj.x / sl, sn[j] = vj.y / sl;
    /* Contact i's directions where its slip keeps its direction (its
     * residual, t x a, zero) and grows, under positive normal forces:
     * bracketed between neighbours of PD_PHASE_START_CELLS directions round
     * the circle, each narrowed by regula falsi (Illinois) along the arc to
     * round-off; the fastest growing taken, as for a lone contact. */
    const double step = 2.0 * M_PI / PD_PHASE_START_CELLS;
    double best = 0.0, bt = 0.0, th0 = 0.0, f0 = 0.0;
    int ok0 = 0;
    for (int k = 0; k <= PD_PHASE_START_CELLS; k++) {
        double th1 = step * k;
        c[i] = cos(th1), sn[i] = sin(th1);
        int ok1 = edge_residual(&e, c, sn, r, along, lambda);
        double f1 = r[i];
        if (ok0 && ok1 && (f0 <= 0.0) != (f1 <= 0.0)) {
            double lo = th0, flo = f0, hi = th1, fhi = f1, m = lo;
            int side = 0, ok = 1;
            for (int it = 0; it < 60 && ok; it++) {
                m = lo + flo / (flo - fhi) * (hi - lo);
                if (!(m > lo && m < hi))
                    break;
                c[i] = cos(m), sn[i] = sin(m);
                ok = edge_residual(&e, c, sn, r, along, lambda);
                double fm = r[i];
                if (fm == 0.0)
                    break;
                int moved_lo = (fm <= 0.0) == (flo <= 0.0);
                if (moved_lo)
                    lo = m, flo = fm;
                else
                    hi = m, fhi = fm;
                pd_illinois_moved(moved_lo, &side, &flo, &fhi);
            }
            c[i] = cos(m), sn[i] = sin(m);
            if (ok && edge_residual(&e, c, sn, r, along, lambda) && lambda[0] > 0.0 &&
                lambda[1] > 0.0 && along[i] > best)
                best = along[i], bt = m;
        }
        th0 = th1, f0 = f1, ok0 = ok1;
    }
    if (!(best > 0.0))
        return 0;
    p->mode[i] = SLIDE;
    p->from_rest[i] = 1;
    p->t0[i] = v3(cos(bt), sin(bt), 0.0);
    p->drill[0] = p->drill[1] = 0.0;
    *accel = best;
    return 1;
}

int pd_phase_forces_of(const pd_phase *p, const pd_state *s, pd_phase_forces *out)
{
    return forces(p, s, 0, out);
}

int pd_phase_forces_general(const pd_phase *p, const pd_state *s, pd_phase_forces *out)
{
    return forces(p, s, 1, out);
}

/* The impulses along the constrained components that change the kinetic
 * energy least: an orthogonal projection in the mass metric, so the energy
 * cannot rise whatever the impulses' signs. */
int pd_phase_project_velocity(const pd_phase *p, pd_state *s)
{
    const pd_body *b = p->b;
    if (!p->mapped)
        return 0;
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    if (p->nc == 1 && p->mode[0] == SLIDE) {
        /* One sliding contact, written out: the impulse x n that stops
         * the normal speed u, x = -u / (n . M n), moves the centre along
         * the world's z. */
        double k = v3_dot(up, m3_vec(CONST_M3(p->M[0][0]), up));
        if (!(fabs(k) > 0.0))
            return 0;
        double x = -(s->v.z + v3_dot(up, v3_cross(s->w, p->r[0]))) / k;
        s->v.z += x / b->mass;
        s->w = v3_add(s->w, pd_body_inv_inertia(b, v3_cross(p->r[0], v3_scale(up, x))));
        return 1;
    }
    const pd_vec3 dir[2] = {up, up};
    layout L;
    make_layout(p, up, dir, body_axes, &L);
    double x[6][6];
    pd_vec3 vb = quat_rotate_inv(s->q, s->v);
    for (int i = 0; i < L.n; i++)
        x[i][0] = -v3_dot(L.row[i], v3_add(vb, v3_cross(s->w, p->r[L.c[i]])));
    if (!solve_layout(p, &L, up, 0, 1, x))
        return 0;
    for (int k = 0; k < L.n; k++) {
        pd_vec3 P = v3_scale(L.col[k], x[k][0]);
        s->v = v3_add(s->v, quat_rotate(s->q, v3_scale(P, 1.0 / b->mass)));
        s->w = v3_add(s->w, pd_body_inv_inertia(b, v3_cross(p->r[L.c[k]], P)));
    }
    return 1;
}
