/* compliant.c: a compliant impact with as many contacts as touch, and the
 * lasting face contact it may turn into (see compliant.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/quat.h"
#include "base/vec3.h"
#include "contact/compliant.h"
#include "contact/contact_tol.h"

struct pd_compliant_work {
    int nverts;
    int ncand;
    int *cand;              /* vertices within the band */
    unsigned char *active;  /* per vertex: below the floor, its law fixed */
    double *k, *lam;        /* per vertex: stiffness, damping (chi / v0) */
    /* per contact pushing in this step */
    int *push;
    double *pn;             /* normal impulse */
    double *ptx, *pty;      /* tangential impulses, accumulated over sweeps */
    double (*kt)[3];        /* the 2 x 2 tangential inverse mass, (xx, xy, yy) */
    pd_vec3 *armx, *army;   /* r x ex, r x ey: the slip along ex is v.x + w.(r x ex) */
    pd_vec3 *turnx, *turny; /* I^-1 (r x ex), I^-1 (r x ey): the turn per unit impulse */
    double (*at)[2];        /* (r.ex, r.ey): the place in the floor's plane */
    int hint;
    const pd_cancel_flag *cancel; /* may be NULL */
};

void pd_compliant_work_watch(pd_compliant_work *w, const pd_cancel_flag *cancel)
{
    w->cancel = cancel;
}

pd_status pd_compliant_init(double e, double T, const pd_body *b, double tol_scale, pd_compliant *c)
{
    if (!(tol_scale > 0.0 && tol_scale <= 1.0))
        return PD_ERR_RANGE;
    pd_compliant_law law;
    pd_status st = pd_compliant_law_init(e, T, &law);
    if (st != PD_OK)
        return st;
    pd_compliant_from_law(&law, b, tol_scale, c);
    return PD_OK;
}

void pd_compliant_from_law(const pd_compliant_law *law, const pd_body *b, double tol_scale,
                           pd_compliant *c)
{
    c->law = *law;
    c->h1 = tol_scale * c->law.step / c->law.omega;
    c->band = PD_COMPLIANT_BAND_REL * b->size;
    c->sweep_tol = tol_scale * PD_COMPLIANT_SWEEP_TOL;
}

pd_compliant_work *pd_compliant_work_alloc(const pd_body *b)
{
    pd_compliant_work *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    size_t n = (size_t)b->nverts;
    w->nverts = b->nverts;
    w->cand = malloc(n * sizeof *w->cand);
    w->active = calloc(n, 1);
    w->k = malloc(n * sizeof *w->k);
    w->lam = malloc(n * sizeof *w->lam);
    w->push = malloc(n * sizeof *w->push);
    w->pn = malloc(n * sizeof *w->pn);
    w->ptx = malloc(n * sizeof *w->ptx);
    w->pty = malloc(n * sizeof *w->pty);
    w->kt = malloc(n * sizeof *w->kt);
    w->armx = malloc(n * sizeof *w->armx);
    w->army = malloc(n * sizeof *w->army);
    w->turnx = malloc(n * sizeof *w->turnx);
    w->turny = malloc(n * sizeof *w->turny);
    w->at = malloc(n * sizeof *w->at);
    if (!w->cand || !w->active || !w->k || !w->lam || !w->push || !w->pn || !w->ptx ||
        !w->pty || !w->kt || !w->armx || !w->army || !w->turnx || !w->turny || !w->at) {
        pd_compliant_work_free(w);
        return NULL;
    }
    return w;
}

void pd_compliant_work_free(pd_compliant_work *w)
{
    if (!w)
        return;
    free(w->cand);
    free(w->active);
    free(w->k);
    free(w->lam);
    free(w->push);
    free(w->pn);
    free(w->ptx);
    free(w->pty);
    free(w->kt);
    free(w->armx);
    free(w->army);
    free(w->turnx);
    free(w->turny);
    free(w->at);
    free(w);
}

/* The larger of a and b, both finite (fmax is a call where it must
 * handle NaN). */
static inline double max2(double a, double b)
{
    return a > b ? a : b;
}

/* The velocity at r2 along c per unit impulse at r1 along a (unit
 * directions, all in the body frame): a.c / m + (r1 x a) I^-1 (r2 x c). */
static double inv_mass2(const pd_body *b, pd_vec3 r1, pd_vec3 a, pd_vec3 r2, pd_vec3 c)
{
    return v3_dot(a, c) / b->mass + v3_dot(v3_cross(r1, a), pd_body_inv_inertia(b, v3_cross(r2, c)));
}

/* The inverse mass of the body at r along a and c. */
static double inv_mass(const pd_body *b, pd_vec3 r, pd_vec3 a, pd_vec3 c)
{
    return inv_mass2(b, r, a, r, c);
}

/* The square of the fastest normal vibration of two contacts i and j on
 * the body, over one contact's (omega^2): the larger eigenvalue of
 * K^1/2 A K^1/2, A their normal inverse masses coupled through the body and
 * K their stiffnesses (a contact not yet touching: the one it will get).
 * At most 2 (the trace bound), 1 + |coupling| when both are as stiff as
 * their touch made them. */
static double pair_mode(const pd_compliant_work *w, const pd_body *b, pd_vec3 up, double omega2,
                        int i, int j)
{
    pd_vec3 ri = b->verts[i], rj = b->verts[j];
    double aii = inv_mass(b, ri, up, up), ajj = inv_mass(b, rj, up, up);
    double aij = inv_mass2(b, ri, up, rj, up);
    double ki = w->active[i] ? w->k[i] : omega2 / aii, kj = w->active[j] ? w->k[j] : omega2 / ajj;
    double p = ki * aii, q = kj * ajj, half = 0.5 * (p - q);
    return (0.5 * (p + q) + sqrt(half * half + ki * kj * aij * aij)) / omega2;
}

static void rebuild_candidates(const pd_compliant *c, pd_compliant_work *w, const pd_body *b,
                               const pd_state *s, pd_vec3 up)
{
    w->ncand = 0;
    for (int i = 0; i < b->nverts; i++) {
        if (s->x.z + v3_dot(b->verts[i], up) < c->band)
            w->cand[w->ncand++] = i;
        else
            w->active[i] = 0;
    }
}

/* Kinetic plus potential energy, J. */
static double energy(const pd_body *b, const pd_state *s, double g)
{
    return pd_body_kinetic(b, s) + b->mass * g * s->x.z;
}

/* The energy the contacts below the floor hold in their springs, J. */
static double elastic_energy(const pd_compliant_work *w, const pd_body *b, const pd_state *s)
{
    pd_vec3 up = quat_rotate_inv(s->q, v3(0, 0, 1));
    double sum = 0.0;
    for (int j = 0; j < w->ncand; j++) {
        int i = w->cand[j];
        double z = s->x.z + v3_dot(b->verts[i], up);
        if (z < 0.0 && w->active[i])
            sum += 0.5 * w->k[i] * z * z;
    }
    return sum;
}

/* Contact j's tangential frame, for the friction solve: its arms (the slip
 * along ex is v.x + w.(r x ex)), its turns (I^-1 of the arms: the spin per
 * unit impulse), its 2 x 2 tangential inverse mass and its place in the
 * floor's plane. */
static void tangent_prepare(pd_compliant_work *w, const pd_body *b, int j, pd_vec3 r, pd_vec3 ex,
                            pd_vec3 ey)
{
    w->armx[j] = v3_cross(r, ex);
    w->army[j] = v3_cross(r, ey);
    w->turnx[j] = pd_body_inv_inertia(b, w->armx[j]);
    w->turny[j] = pd_body_inv_inertia(b, w->army[j]);
    w->kt[j][0] = 1.0 / b->mass + v3_dot(w->armx[j], w->turnx[j]);
    w->kt[j][1] = v3_dot(w->armx[j], w->turny[j]);
    w->kt[j][2] = 1.0 / b->mass + v3_dot(w->army[j], w->turny[j]);
    w->at[j][0] = v3_dot(r, ex);
    w->at[j][1] = v3_dot(r, ey);
}

/* Adds the tangential impulse (dx, dy) at contact j to the body's motion. */
static void push_tangent(const pd_compliant_work *w, int j, double m, double dx, double dy,
                         pd_vec3 *v, pd_vec3 *wv)
{
    v->x += dx / m;
    v->y += dy / m;
    *wv = v3_add(*wv, v3_add(v3_scale(w->turnx[j], dx), v3_scale(w->turny[j], dy)));
}

/* Coulomb friction by Gauss-Seidel sweeps, the contacts coupled through the
 * body: at each pushing contact the tangential impulse that stops its slip
 * (the slip it would have without its own friction this step), if that lies
 * within the cone; else the cone's impulse against the slip's direction, no
 * larger than stops the slip along that direction. The direction matters:
 * the cone's point nearest the stopping impulse is not against the slip
 * where the tangential inverse mass is anisotropic, and that error does not
 * shrink with the step (it moved a sliding impact's outgoing velocities by
 * up to 2% of their size at any step). Stops when no impulse moved more than
 * stop in a sweep; returns the sweeps made, or -1 if max_sweeps stopped
 * them. With stuck set, also stops after the first sweep that leaves every
 * impulse within its cone without converging, returning -1 less the sweeps
 * made. */
static int friction_sweeps(pd_compliant_work *w, int n, double m, double mu, double stop,
                           int max_sweeps, int fresh, int stuck, pd_vec3 *v, pd_vec3 *wv)
{
    if (fresh)
        for (int j = 0; j < n; j++)
            w->ptx[j] = w->pty[j] = 0.0;
    for (int sweep = 0; sweep < max_sweeps; sweep++) {
        double change = 0.0;
        int inside = 1;
        for (int j = 0; j < n; j++) {
            double ux = v->x + v3_dot(*wv, w->armx[j]);
            double uy = v->y + v3_dot(*wv, w->army[j]);
            double kxx = w->kt[j][0], kxy = w->kt[j][1], kyy = w->kt[j][2];
            double det = kxx * kyy - kxy * kxy;
            double fx = ux - (kxx * w->ptx[j] + kxy * w->pty[j]);
            double fy = uy - (kxy * w->ptx[j] + kyy * w->pty[j]);
            double px = -(kyy * fx - kxy * fy) / det, py = -(kxx * fy - kxy * fx) / det;
            double cap = mu * w->pn[j];
            if (px * px + py * py > cap * cap) {
                inside = 0;
                /* hypot only where the squares underflow: it costs as much
                 * as the rest of the sweep. */
                double fn = sqrt(fx * fx + fy * fy);
                if (!(fn > 0.0))
                    fn = hypot(fx, fy);
                double ax = fx / fn, ay = fy / fn;
                double kaa = kxx * ax * ax + 2.0 * kxy * ax * ay + kyy * ay * ay;
                double mag = fmin(cap, fn / kaa);
                px = -mag * ax;
                py = -mag * ay;
            }
            double ddx = px - w->ptx[j], ddy = py - w->pty[j];
            w->ptx[j] = px;
            w->pty[j] = py;
            push_tangent(w, j, m, ddx, ddy, v, wv);
            change = max2(change, max2(fabs(ddx), fabs(ddy)));
        }
        /* One contact: the slip without its own friction, which sets its
         * impulse, does not depend on that impulse, so one sweep is
         * converged and another would only re-derive it to round-off. */
        if (change <= stop || n == 1)
            return sweep + 1;
        if (stuck && inside)
            return -2 - sweep;
    }
    return -1;
}

/* The interval of s where |p + s d| <= cap (d != 0), intersected into
 * [*lo, *hi]; 0 if it is empty. */
static int cone_interval(double px, double py, double dx, double dy, double cap, double *lo,
                         double *hi)
{
    double a = dx * dx + dy * dy, bh = px * dx + py * dy, c = px * px + py * py - cap * cap;
    double disc = bh * bh - a * c;
    if (!(disc >= 0.0) || !(a > 0.0))
        return 0;
    double root = sqrt(disc);
    *lo = max2(*lo, (-bh - root) / a);
    *hi = fmin(*hi, (-bh + root) / a);
    return *lo <= *hi;
}

/* Solves A x = y in place for A symmetric positive definite 3 x 3, given
 * by its Cholesky factor L (lower, row by row). */
static void chol3_solve(double L[3][3], double x[3])
{
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k < i; k++)
            x[i] -= L[i][k] * x[k];
        x[i] /= L[i][i];
    }
    for (int i = 2; i >= 0; i--) {
        for (int k = i + 1; k < 3; k++)
            x[i] -= L[k][i] * x[k];
        x[i] /= L[i][i];
    }
}

/* Two contacts both sticking, in closed form. Their four slips are not
 * independent: the segment between them lies in the floor's plane (to the
 * depth they are pressed in), so a rigid body's two points move alike
 * along it, and equal and opposite impulses along it (the squeeze) move
 * the body not at all. So three slips are stopped, the common one along
 * the segment and each one across it, by the least impulse that does
 * (a 3 x 3 solve in the impulses orthogonal to the squeeze), and the
 * squeeze is then free: the one nearest none that brings both impulses
 * within their cones (each cone a quadratic in the squeeze, an interval).
 * The squeeze is taken along the direction that leaves the three stopped
 * slips stopped (the squeeze less its coupling to them), which is the
 * squeeze itself when the contacts are at one depth. Returns 1 with the
 * impulses applied to v and wv and left in ptx, pty; 0 if no squeeze
 * brings both within their cones (a contact slides) or the contacts are at
 * one point of the floor's plane, nothing changed. */
static int friction_pair_stick(pd_compliant_work *w, double m, double mu, pd_vec3 *v,
                               pd_vec3 *wv)
{
    double tx = w->at[0][0] - w->at[1][0], ty = w->at[0][1] - w->at[1][1];
    double tn = sqrt(tx * tx + ty * ty);
    if (!(tn > 0.0))
        return 0;
    tx /= tn;
    ty /= tn;
    const double h = sqrt(0.5);
    /* The impulses (p0x, p0y, p1x, p1y) orthogonal to the squeeze q: along
     * the segment at both, across it at one, across it at the other. */
    const double B[4][3] = {{h * tx, -ty, 0.0}, {h * ty, tx, 0.0},
                            {h * tx, 0.0, -ty}, {h * ty, 0.0, tx}};
    const double q[4] = {h * tx, h * ty, -h * tx, -h * ty};
    const pd_vec3 arm[4] = {w->armx[0], w->army[0], w->armx[1], w->army[1]};
    const pd_vec3 turn[4] = {w->turnx[0], w->turny[0], w->turnx[1], w->turny[1]};
    double K[4][4], u[4];
    for (int a = 0; a < 4; a++) {
        u[a] = ((a & 1) ? v->y : v->x) + v3_dot(*wv, arm[a]);
        for (int c = a; c < 4; c++)
            K[a][c] = K[c][a] = ((a & 1) == (c & 1) ? 1.0 / m : 0.0) + v3_dot(arm[a], turn[c]);
    }
    double KB[4][3], Kq[4], A[3][3], y[3], z[3];
    for (int a = 0; a < 4; a++) {
        Kq[a] = 0.0;
        for (int c = 0; c < 4; c++)
            Kq[a] += K[a][c] * q[c];
        for (int i = 0; i < 3; i++) {
            KB[a][i] = 0.0;
            for (int c = 0; c < 4; c++)
                KB[a][i] += K[a][c] * B[c][i];
        }
    }
    for (int i = 0; i < 3; i++) {
        y[i] = z[i] = 0.0;
        for (int a = 0; a < 4; a++) {
            y[i] -= B[a][i] * u[a];
            z[i] += B[a][i] * Kq[a];
        }
        for (int k = 0; k < 3; k++) {
            A[i][k] = 0.0;
            for (int a = 0; a < 4; a++)
                A[i][k] += B[a][i] * KB[a][k];
        }
    }
    double L[3][3] = {{0}}, trace = A[0][0] + A[1][1] + A[2][2];
    for (int i = 0; i < 3; i++) {
        for (int k = 0; k <= i; k++) {
            double sum = A[i][k];
            for (int l = 0; l < k; l++)
                sum -= L[i][l] * L[k][l];
            if (k < i) {
                L[i][k] = sum / L[k][k];
            } else {
                if (!(sum > PD_COMPLIANT_PAIR_PIVOT_REL * trace))
                    return 0;
                L[i][i] = sqrt(sum);
            }
        }
    }
    chol3_solve(L, y);
    chol3_solve(L, z);
    double p[4], d[4];
    for (int a = 0; a < 4; a++) {
        p[a] = d[a] = 0.0;
        for (int i = 0; i < 3; i++) {
            p[a] += B[a][i] * y[i];
            d[a] -= B[a][i] * z[i];
        }
        d[a] += q[a];
    }
    double lo = -INFINITY, hi = INFINITY;
    if (!cone_interval(p[0], p[1], d[0], d[1], mu * w->pn[0], &lo, &hi) ||
        !cone_interval(p[2], p[3], d[2], d[3], mu * w->pn[1], &lo, &hi))
        return 0;
    double sq = lo > 0.0 ? lo : hi < 0.0 ? hi : 0.0;
    for (int a = 0; a < 4; a++)
        p[a] += sq * d[a];
    for (int j = 0; j < 2; j++) {
        w->ptx[j] = p[2 * j];
        w->pty[j] = p[2 * j + 1];
        push_tangent(w, j, m, p[2 * j], p[2 * j + 1], v, wv);
    }
    return 1;
}

/* The step's friction by the sweeps; with pair set, two contacts whose
 * sweeps have not converged by the first sweep that leaves both within
 * their cones, or by PD_COMPLIANT_PAIR_AFTER sweeps, are solved in closed
 * form if both can stick, else their sweeps go on. The closed form depends
 * on the step's velocities alone, not on the sweeps so far, so it is tried
 * once. Returns the sweeps made (0: the closed form), or -1 if max_sweeps
 * stopped them. pair 2 tries the closed form first (for tests). */
static int friction(pd_compliant_work *w, int n, double m, double mu, double stop, int max_sweeps,
                    int pair, pd_vec3 *v, pd_vec3 *wv)
{
    if (pair == 2 && n == 2 && friction_pair_stick(w, m, mu, v, wv))
        return 0;
    if (pair != 1 || n != 2 || max_sweeps <= PD_COMPLIANT_PAIR_AFTER)
        return friction_sweeps(w, n, m, mu, stop, max_sweeps, 1, 0, v, wv);
    pd_vec3 v0 = *v, w0 = *wv;
    int made = friction_sweeps(w, n, m, mu, stop, PD_COMPLIANT_PAIR_AFTER, 1, 1, v, wv);
    if (made >= 0)
        return made;
    int done = made == -1 ? PD_COMPLIANT_PAIR_AFTER : -1 - made;
    double kept[4] = {w->ptx[0], w->pty[0], w->ptx[1], w->pty[1]};
    if (friction_pair_stick(w, m, mu, &v0, &w0)) {
        *v = v0;
        *wv = w0;
        return 0;
    }
    w->ptx[0] = kept[0];
    w->pty[0] = kept[1];
    w->ptx[1] = kept[2];
    w->pty[1] = kept[3];
    made = friction_sweeps(w, n, m, mu, stop, max_sweeps - done, 0, 0, v, wv);
    return made < 0 ? -1 : made + done;
}

int pd_compliant_friction(pd_compliant_work *w, const pd_body *b, int n, const pd_vec3 *r,
                          const double *pn, pd_vec3 ex, pd_vec3 ey, double mu, double tol,
                          int sweeps, int pair, pd_vec3 *v, pd_vec3 *wv, double *p)
{
    double pn_max = 0.0;
    for (int j = 0; j < n; j++) {
        w->pn[j] = pn[j];
        pn_max = max2(pn_max, pn[j]);
        tangent_prepare(w, b, j, r[j], ex, ey);
    }
    int made = friction(w, n, b->mass, mu, tol * mu * pn_max, sweeps, pair, v, wv);
    for (int j = 0; j < n; j++) {
        p[2 * j] = w->ptx[j];
        p[2 * j + 1] = w->pty[j];
    }
    return made;
}

pd_status pd_compliant_run(const pd_compliant *c, pd_compliant_work *w, const pd_settle *settle,
                           const pd_scene *sc, pd_state *s, double t_max, pd_compliant_result *r)
{
    const pd_body *b = settle->body;
    const double g = sc->gravity, mu = sc->mu, m = b->mass;
    const double omega2 = c->law.omega * c->law.omega, chi = c->law.chi;
    const double v_rest = settle->v_rest;
    memset(r, 0, sizeof *r);
    r->pose = -1;

    /* Enter with no vertex below the floor (the impact search leaves the
     * lowest within its tolerance, either side). */
    pd_vec3 up = quat_rotate_inv(s->q, v3(0, 0, 1));
    int low = pd_body_support(b, up, w->hint >= 0 && w->hint < b->nverts ? w->hint : 0);
    double zlow = s->x.z + v3_dot(b->verts[low], up);
    if (zlow < 0.0)
        s->x.z -= zlow;
    const double e_start = energy(b, s, g);
    memset(w->active, 0, (size_t)b->nverts);
    rebuild_candidates(c, w, b, s, up);

    double t = 0.0, last_touch = 0.0, moved = 0.0, h = c->h1;
    for (long step = 0;; step++) {
        /* The world's axes in the body frame: the rows of the rotation. */
        double R[3][3];
        quat_to_matrix(s->q, R);
        up = v3(R[2][0], R[2][1], R[2][2]);
        pd_vec3 ex = v3(R[0][0], R[0][1], R[0][2]), ey = v3(R[1][0], R[1][1], R[1][2]);
        int npush = 0, nbelow = 0, arriving = 0, entering = 0, pair[2] = {-1, -1};
        double deepest = 0.0, speed = 0.0, load = 0.0, elastic = 0.0;
        for (int j = 0; j < w->ncand; j++) {
            int i = w->cand[j];
            pd_vec3 r_i = b->verts[i];
            double z = s->x.z + v3_dot(r_i, up);
            double uz = s->v.z + v3_dot(v3_cross(s->w, r_i), up);
            if (z >= 0.0) {
                w->active[i] = 0;
                if (uz < 0.0 && z < -2.0 * uz * h)
                    arriving = 1;
                if (uz < 0.0 && z < -uz * c->h1) {
                    if (nbelow + entering < 2)
                        pair[nbelow + entering] = i;
                    entering++;
                }
                continue;
            }
            if (!w->active[i]) {
                /* Touching now: its law, from its effective mass and its
                 * approach speed (resting contact's at least, so that a
                 * contact creeping in is not damped without bound). */
                w->active[i] = 1;
                w->k[i] = omega2 / inv_mass(b, r_i, up, up);
                w->lam[i] = chi / fmax(-uz, v_rest);
                last_touch = t;
            }
            double d = -z;
            if (nbelow + entering < 2)
                pair[nbelow + entering] = i;
            nbelow++;
            deepest = max2(deepest, d);
            speed = max2(speed, fabs(uz));
            load = max2(load, w->k[i] * d);
            elastic += 0.5 * w->k[i] * d * d;
            double f = w->k[i] * d * (1.0 + w->lam[i] * (-uz));
            if (f > 0.0) {
                w->push[npush] = i;
                w->pn[npush] = f;
                npush++;
            }
        }
        if (nbelow > 0 && speed <= v_rest && load <= PD_COMPLIANT_REST_LOAD * m * g)
            r->rest_depth = fmax(r->rest_depth, deepest);
        if (step > 0) {
            if (nbelow == 0 && !arriving) {
                r->end = PD_COMPLIANT_SEPARATED;
                break;
            }
            if (nbelow <= 2 && t - last_touch >= c->law.T && speed <= v_rest &&
                load <= PD_COMPLIANT_REST_LOAD * m * g) {
                r->end = PD_COMPLIANT_QUIET;
                break;
            }
            if (step % PD_COMPLIANT_TEST_EVERY == 0) {
                /* The outcome of the state with its compression undone and
                 * its elastic energy counted as height: never lower than the
                 * energy the part has. */
                pd_state lifted = *s;
                lifted.x.z += deepest + elastic / (m * g);
                int pose;
                int d = pd_settle_outcome(settle, &lifted, g, mu, &w->hint, &pose);
                if (d < 0)
                    return PD_ERR_INTERNAL;
                if (d > 0) {
                    r->end = PD_COMPLIANT_DECIDED;
                    r->pose = pose;
                    break;
                }
            }
        }
        if (t >= t_max) {
            r->end = PD_COMPLIANT_TIME;
            break;
        }
        if (w->cancel && atomic_load_explicit(w->cancel, memory_order_relaxed)) {
            r->end = PD_COMPLIANT_CANCELLED;
            break;
        }

        /* Counting the contacts that come below within the step: a face
         * landing flat must not take its first step in contact at one
         * contact's length. Two: their fastest mode exactly (a closed
         * form; on a cube's edge about 1.14 times one contact's square
         * against the bound's 2); more: the trace bound n. */
        int n = nbelow + entering;
        double stiff = n == 2 ? pair_mode(w, b, up, omega2, pair[0], pair[1]) : (double)n;
        h = c->h1 / sqrt(stiff > 1.0 ? stiff : 1.0);
        /* Gravity and the normal impulses. */
        pd_vec3 dv = v3(0, 0, -g * h), dw = v3(0, 0, 0);
        double pn_max = 0.0;
        for (int j = 0; j < npush; j++) {
            int i = w->push[j];
            double p = w->pn[j] * h;
            w->pn[j] = p;
            pn_max = fmax(pn_max, p);
            dv.z += p / m;
            dw = v3_add(dw, v3_cross(b->verts[i], v3_scale(up, p)));
        }
        s->v = v3_add(s->v, dv);
        /* Torque-free precession (Euler's equations, explicit) and the
         * contacts' torque. */
        pd_vec3 wo = s->w;
        s->w = v3_add(s->w, v3(h * b->euler[0] * wo.y * wo.z, h * b->euler[1] * wo.z * wo.x,
                               h * b->euler[2] * wo.x * wo.y));
        s->w = v3_add(s->w, pd_body_inv_inertia(b, dw));

        /* Coulomb friction at every pushing contact. */
        if (mu > 0.0 && npush > 0) {
            for (int j = 0; j < npush; j++)
                tangent_prepare(w, b, j, b->verts[w->push[j]], ex, ey);
            friction(w, npush, m, mu, c->sweep_tol * mu * pn_max, PD_COMPLIANT_SWEEPS, 1, &s->v,
                     &s->w);
        }

        /* Positions from the new velocities (the symplectic half). */
        s->x = v3_add(s->x, v3_scale(s->v, h));
        s->q = quat_normalize(quat_mul(s->q, quat_exp(v3_scale(s->w, h))));
        t += h;
        r->steps++;
        if (!v3_isfinite(s->x) || !v3_isfinite(s->v) || !v3_isfinite(s->w))
            return PD_ERR_NONFINITE;
        moved += (v3_norm(s->v) + v3_norm(s->w) * b->rmax) * h;
        if (moved > 0.5 * c->band) {
            rebuild_candidates(c, w, b, s, quat_rotate_inv(s->q, v3(0, 0, 1)));
            moved = 0.0;
        }
    }
    r->time = t;
    /* The law and friction only take energy; the explicit step may add some
     * of its own error (most with e near 1, where nothing damps it). Never
     * let the run end with more than it began with, elastic energy counted:
     * the outcome test relies on it. */
    double e_end = energy(b, s, g) + elastic_energy(w, b, s);
    if (r->end != PD_COMPLIANT_DECIDED && e_end > e_start) {
        double kin = pd_body_kinetic(b, s), excess = e_end - e_start;
        double f = kin > excess ? sqrt((kin - excess) / kin) : 0.0;
        s->v = v3_scale(s->v, f);
        s->w = v3_scale(s->w, f);
        r->energy_gain = 1;
    }
    if (r->end == PD_COMPLIANT_QUIET) {
        /* Onto the floor for the contact phases: raises the part by its
         * static compression, about g / omega^2, 2e-5 of a 1 cm part at the
         * default contact time, less the elastic energy it held. */
        up = quat_rotate_inv(s->q, v3(0, 0, 1));
        int lowest = pd_body_support(b, up, w->ncand > 0 ? w->cand[0] : 0);
        s->x.z -= fmin(0.0, s->x.z + v3_dot(b->verts[lowest], up));
    }
    return PD_OK;
}
