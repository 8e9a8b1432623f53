/* design.c: a part changed to meet a goal (posedrop/design.h).
 *
 * The search runs in x, the changes' values mapped onto [0, 1] (a factor
 * by its logarithm, so that 0.5 and 2 are as far from 1). Its objective
 * is a sum of squared residuals r(x): a target's p_t - target_t, an
 * equalisation's p_t - mean(p), a maximum's 1 - sum p_t, whose square
 * falls as the sum rises.
 *  1. Static scan: the objective on a grid (17 points for one change, 9 x 9
 *     for two, 64 quasi-random points for more) and the part as given.
 *  2. Static search: Levenberg-Marquardt from the three best points of the
 *     scan, each step solving (J'J + lambda I) dx = -J'r with the exact
 *     Jacobian of the static model (tangent.c through the changes' motion,
 *     change.c), the step projected into the box.
 *  3. Drops: the same residuals from drops of one seed at every point
 *     (common random numbers, so that two points differ by what changed
 *     and not by fresh noise). A target or an equalisation takes Gauss-
 *     Newton steps with the static Jacobian as the first guess, corrected
 *     by Broyden's update from each step's observed change; a maximum
 *     takes GSL's Nelder-Mead simplex, whose comparisons of points need
 *     no gradient.
 *  4. Check: fresh drops of another seed at the result, Wilson intervals. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/gsl_adapter.h"
#include "base/stats.h"
#include "base/vec3.h"
#include "design/design_match.h"
#include "posedrop/symmetry.h"
#include "static/tangent.h"

#define MAX_TARGETS 64
#define MAX_STARTS 3
#define LM_MAX_ITER 100

void pd_design_options_default(pd_design_options *o)
{
    if (!o)
        return;
    memset(o, 0, sizeof *o);
    pd_static_options_default(&o->statics);
    o->model = PD_DESIGN_PQS;
    pd_scene_default(&o->scene);
    pd_sim_options_default(&o->sim);
    o->sim.ndrops = 20000;
    o->max_evals = 12;
    o->check_drops = 20000;
    o->check_seed = 2;
}

void pd_design_result_free(pd_design_result *r)
{
    if (!r)
        return;
    free(r->targets);
    pd_part_free(r->part);
    free(r);
}

typedef struct run {
    design_ctx ctx;
    const pd_design_options *o;
    pd_design_goal goal;
    int nt, d;
    int facet[MAX_TARGETS];     /* the base facet each target names */
    double target[MAX_TARGETS];
    int *mark;                  /* scratch for design_match_facet */
    int static_evals, drop_evals;
    long drops;
    pd_diag *diag;
    pd_status st;               /* the first hard failure */
    int partial;                /* the drops were cancelled (options.sim.cancel) */
} run;

/* One evaluated point: the changed part, its static estimate, and each
 * target's member poses (member[t * nposes + j]). */
typedef struct point {
    pd_part *part;
    pd_static_result *res;
    unsigned char *member;
} point;

static void point_free(point *p)
{
    free(p->member);
    pd_static_result_free(p->res);
    pd_part_free(p->part);
    memset(p, 0, sizeof *p);
}

static void values_of(const run *R, const double *x, double *value)
{
    for (int k = 0; k < R->d; k++) {
        double u = R->ctx.lo[k] + fmin(1.0, fmax(0.0, x[k])) * (R->ctx.hi[k] - R->ctx.lo[k]);
        value[k] = R->ctx.changes[k].kind == PD_CHANGE_SCALE ? exp(u) : u;
    }
}

/* d value_k / d x_k. */
static double value_rate(const run *R, int k, double value)
{
    double w = R->ctx.hi[k] - R->ctx.lo[k];
    return R->ctx.changes[k].kind == PD_CHANGE_SCALE ? w * value : w;
}

/* Builds the part at value and finds each target's poses. A part the
 * change cannot build (an offset out of the part, a vertex welded) is no
 * point: PD_ERR_RANGE, quietly. */
static pd_status point_at(run *R, const double *value, point *p)
{
    memset(p, 0, sizeof *p);
    pd_diag quiet;
    pd_diag_init(&quiet);
    pd_status st = design_build(&R->ctx, value, &p->part, &quiet);
    if (st == PD_ERR_NOMEM)
        return R->st = pd_fail(R->diag, st, "design: out of memory");
    if (st != PD_OK)
        return PD_ERR_RANGE;
    st = pd_static_estimate(p->part, &R->o->statics, &p->res, &quiet);
    if (st != PD_OK) {
        point_free(p);
        return st == PD_ERR_NOMEM ? (R->st = pd_fail(R->diag, st, "design: out of memory"))
                                  : PD_ERR_RANGE;
    }
    int np = p->res->nposes;
    int *class_of = malloc(sizeof *class_of * (size_t)(np + 1));
    p->member = calloc((size_t)(R->nt * np + 1), 1);
    if (!class_of || !p->member) {
        free(class_of);
        point_free(p);
        return R->st = pd_fail(R->diag, PD_ERR_NOMEM, "design: out of memory");
    }
    int nc = np;
    for (int j = 0; j < np; j++)
        class_of[j] = j;
    if (R->o->group && np > 0 && pd_pose_classes(p->part, p->res, class_of, &nc, &quiet) != PD_OK)
        for (int j = 0; j < np; j++)
            class_of[j] = j;
    for (int t = 0; t < R->nt; t++) {
        int g = design_match_facet(R->ctx.base, R->facet[t], p->part, R->mark);
        int pose = -1;
        for (int j = 0; g >= 0 && j < np; j++)
            if (p->res->poses[j].facet == g)
                pose = j;
        for (int j = 0; pose >= 0 && j < np; j++)
            p->member[t * np + j] = class_of[j] == class_of[pose];
    }
    free(class_of);
    return PD_OK;
}

/* The targets' static probabilities at p (which 0: QS, 1: PQS). */
static void static_p(const run *R, const point *p, int which, double *pt)
{
    int np = p->res->nposes;
    for (int t = 0; t < R->nt; t++) {
        pt[t] = 0.0;
        for (int j = 0; j < np; j++)
            if (p->member[t * np + j])
                pt[t] += which ? p->res->poses[j].p_pqs : p->res->poses[j].p_qs;
    }
}

/* Residuals of the targets' probabilities pt, and their Jacobian rows from
 * dpt (nt x d, row-major) when both are given. Returns their number. */
static int residuals(const run *R, const double *pt, const double *dpt, double *r, double *J)
{
    int d = R->d;
    if (R->goal == PD_GOAL_MAXIMISE) {
        r[0] = 1.0;
        for (int k = 0; J && k < d; k++)
            J[k] = 0.0;
        for (int t = 0; t < R->nt; t++) {
            r[0] -= pt[t];
            for (int k = 0; J && k < d; k++)
                J[k] -= dpt[t * d + k];
        }
        return 1;
    }
    double mean = 0.0, dmean[PD_DESIGN_MAX_CHANGES] = {0};
    for (int t = 0; t < R->nt; t++) {
        mean += pt[t] / R->nt;
        for (int k = 0; J && k < d; k++)
            dmean[k] += dpt[t * d + k] / R->nt;
    }
    int eq = R->goal == PD_GOAL_EQUALISE;
    for (int t = 0; t < R->nt; t++) {
        r[t] = pt[t] - (eq ? mean : R->target[t]);
        for (int k = 0; J && k < d; k++)
            J[t * d + k] = dpt[t * d + k] - (eq ? dmean[k] : 0.0);
    }
    return R->nt;
}

static double sumsq(const double *r, int m)
{
    double s = 0.0;
    for (int i = 0; i < m; i++)
        s += r[i] * r[i];
    return s;
}

/* The static objective at x, and with J its residuals' Jacobian in x (r,
 * J may be NULL). HUGE_VAL where no part can be built. */
static double static_eval(run *R, const double *x, double *r, double *J, int *m)
{
    double value[PD_DESIGN_MAX_CHANGES], pt[MAX_TARGETS], rr[MAX_TARGETS];
    double *dpt = NULL;
    point p;
    values_of(R, x, value);
    R->static_evals++;
    if (point_at(R, value, &p) != PD_OK)
        return HUGE_VAL;
    int which = R->o->model == PD_DESIGN_PQS;
    static_p(R, &p, which, pt);
    if (J) {
        const pd_hull *h = p.part->hull;
        int np = p.res->nposes;
        pd_vec3 *dv = malloc(sizeof *dv * (size_t)h->nverts);
        double *df = malloc(sizeof *df * (size_t)h->nfacets);
        dpt = calloc((size_t)(R->nt * R->d), sizeof *dpt);
        if (!dv || !df || !dpt) {
            R->st = pd_fail(R->diag, PD_ERR_NOMEM, "design: out of memory");
            free(dv);
            free(df);
            free(dpt);
            point_free(&p);
            return HUGE_VAL;
        }
        for (int k = 0; k < R->d; k++) {
            pd_vec3 dcom;
            design_motion(&R->ctx, p.part, k, dv, &dcom);
            pd_static_tangent(h, p.part->com, &R->o->statics, p.res, dv, dcom, NULL,
                              which ? NULL : df, which ? df : NULL);
            double rate = value_rate(R, k, value[k]);
            for (int t = 0; t < R->nt; t++)
                for (int j = 0; j < np; j++)
                    if (p.member[t * np + j])
                        dpt[t * R->d + k] += df[p.res->poses[j].facet] * rate;
        }
        free(dv);
        free(df);
    }
    int mm = residuals(R, pt, dpt, r ? r : rr, J);
    if (m)
        *m = mm;
    free(dpt);
    point_free(&p);
    return sumsq(r ? r : rr, mm);
}

/* Solves (A + lambda I) x = b, A symmetric positive semi-definite (d x d),
 * by Cholesky; 0 if not positive definite. */
static int solve_damped(const double *A, double lambda, const double *b, int d, double *x)
{
    double L[PD_DESIGN_MAX_CHANGES * PD_DESIGN_MAX_CHANGES];
    for (int i = 0; i < d; i++)
        for (int j = 0; j <= i; j++) {
            double s = A[i * d + j] + (i == j ? lambda : 0.0);
            for (int k = 0; k < j; k++)
                s -= L[i * d + k] * L[j * d + k];
            if (i == j) {
                if (!(s > 0.0))
                    return 0;
                L[i * d + i] = sqrt(s);
            } else {
                L[i * d + j] = s / L[j * d + j];
            }
        }
    double y[PD_DESIGN_MAX_CHANGES];
    for (int i = 0; i < d; i++) {
        double s = b[i];
        for (int k = 0; k < i; k++)
            s -= L[i * d + k] * y[k];
        y[i] = s / L[i * d + i];
    }
    for (int i = d - 1; i >= 0; i--) {
        double s = y[i];
        for (int k = i + 1; k < d; k++)
            s -= L[k * d + i] * x[k];
        x[i] = s / L[i * d + i];
    }
    return 1;
}

/* The damped Gauss-Newton step from residuals r (m) and Jacobian J (m x d),
 * projected into the box: x1 = clamp(x + dx). */
static void lm_step(const double *x, const double *r, const double *J, int m, int d,
                    double lambda, double *x1)
{
    double A[PD_DESIGN_MAX_CHANGES * PD_DESIGN_MAX_CHANGES], g[PD_DESIGN_MAX_CHANGES],
           dx[PD_DESIGN_MAX_CHANGES];
    for (int i = 0; i < d; i++) {
        g[i] = 0.0;
        for (int t = 0; t < m; t++)
            g[i] -= J[t * d + i] * r[t];
        for (int j = 0; j < d; j++) {
            A[i * d + j] = 0.0;
            for (int t = 0; t < m; t++)
                A[i * d + j] += J[t * d + i] * J[t * d + j];
        }
    }
    if (!solve_damped(A, lambda, g, d, dx))
        for (int i = 0; i < d; i++)
            dx[i] = 0.0;
    for (int i = 0; i < d; i++)
        x1[i] = fmin(1.0, fmax(0.0, x[i] + dx[i]));
}

/* Levenberg-Marquardt on the static model from x (overwritten). */
static double static_search(run *R, double *x)
{
    int d = R->d, m;
    double r[MAX_TARGETS], J[MAX_TARGETS * PD_DESIGN_MAX_CHANGES], x1[PD_DESIGN_MAX_CHANGES];
    double f = static_eval(R, x, r, J, &m), lambda = 1e-3;
    for (int it = 0; it < LM_MAX_ITER && isfinite(f) && f > 1e-24 && R->st == PD_OK; it++) {
        lm_step(x, r, J, m, d, lambda, x1);
        double moved = 0.0;
        for (int k = 0; k < d; k++)
            moved = fmax(moved, fabs(x1[k] - x[k]));
        if (moved < 1e-12) {
            if (lambda > 1e6)
                break;
            lambda *= 10.0;
            continue;
        }
        double r1[MAX_TARGETS], J1[MAX_TARGETS * PD_DESIGN_MAX_CHANGES];
        double f1 = static_eval(R, x1, r1, J1, &m);
        if (f1 < f) {
            memcpy(x, x1, sizeof(double) * (size_t)d);
            memcpy(r, r1, sizeof r1);
            memcpy(J, J1, sizeof J1);
            double gain = f - f1;
            f = f1;
            lambda = fmax(lambda / 3.0, 1e-12);
            if (gain < 1e-15 * fmax(f, 1e-300) && moved < 1e-9)
                break;
        } else {
            lambda *= 4.0;
            if (lambda > 1e10)
                break;
        }
    }
    return f;
}

/* The radical inverse of i in base b: the scan's quasi-random points. */
static double radical_inverse(int i, int b)
{
    double f = 1.0, r = 0.0;
    for (; i > 0; i /= b) {
        f /= b;
        r += f * (i % b);
    }
    return r;
}

static void progress(const run *R, const char *stage, int evals, double f)
{
    if (R->o->progress)
        R->o->progress(R->o->progress_user, stage, evals, f);
}

/* Stages 1 and 2: the static optimum into x; its objective. */
static double static_stage(run *R, const double *x0, double *x)
{
    int d = R->d;
    static const int primes[PD_DESIGN_MAX_CHANGES] = {2, 3, 5, 7, 11, 13, 17, 19, 23};
    int npts = d == 1 ? 17 : d == 2 ? 81 : 64;
    double best_f[MAX_STARTS], best_x[MAX_STARTS][PD_DESIGN_MAX_CHANGES];
    for (int s = 0; s < MAX_STARTS; s++)
        best_f[s] = HUGE_VAL;
    for (int i = -1; i < npts && R->st == PD_OK; i++) {
        double y[PD_DESIGN_MAX_CHANGES];
        for (int k = 0; k < d; k++)
            y[k] = i < 0 ? x0[k]
                 : d == 1 ? i / 16.0
                 : d == 2 ? (k == 0 ? i % 9 : i / 9) / 8.0
                          : radical_inverse(i + 1, primes[k]);
        double f = static_eval(R, y, NULL, NULL, NULL);
        for (int s = 0; s < MAX_STARTS; s++)
            if (f < best_f[s]) {
                for (int u = MAX_STARTS - 1; u > s; u--) {
                    best_f[u] = best_f[u - 1];
                    memcpy(best_x[u], best_x[u - 1], sizeof best_x[u]);
                }
                best_f[s] = f;
                memcpy(best_x[s], y, sizeof y);
                break;
            }
    }
    progress(R, "scan", R->static_evals, best_f[0]);
    double f = HUGE_VAL;
    for (int s = 0; s < MAX_STARTS && isfinite(best_f[s]) && R->st == PD_OK; s++) {
        double y[PD_DESIGN_MAX_CHANGES];
        memcpy(y, best_x[s], sizeof y);
        double fs = static_search(R, y);
        if (fs < f) {
            f = fs;
            memcpy(x, y, sizeof y);
        }
        progress(R, "static", R->static_evals, f);
    }
    return f;
}

/* The targets' probabilities from drops of seed at x (n of them); each
 * drop's target by its pose. HUGE_VAL objective where no part is built. */
static double drop_eval(run *R, const double *x, long n, uint64_t seed, double *pt, long *count,
                        double *r, int *m)
{
    double value[PD_DESIGN_MAX_CHANGES];
    point p;
    values_of(R, x, value);
    if (point_at(R, value, &p) != PD_OK)
        return HUGE_VAL;
    pd_sim_options so = R->o->sim;
    so.ndrops = n;
    so.seed = seed;
    so.keep_trials = 0;
    so.ci_halfwidth = 0.0;
    pd_sim_result *s = NULL;
    pd_status st = pd_sim_run(p.part, p.res, &R->o->scene, &so, &s, R->diag);
    if (st != PD_OK) {
        R->st = st;
        point_free(&p);
        return HUGE_VAL;
    }
    R->drops += s->n;
    R->partial |= s->partial;
    int np = p.res->nposes;
    for (int t = 0; t < R->nt; t++) {
        long c = 0;
        for (int j = 0; j < np; j++)
            if (p.member[t * np + j])
                c += s->count[j];
        if (count)
            count[t] = c;
        pt[t] = s->n > 0 ? (double)c / (double)s->n : 0.0;
    }
    pd_sim_result_free(s);
    point_free(&p);
    double rr[MAX_TARGETS];
    int mm = residuals(R, pt, NULL, r ? r : rr, NULL);
    if (m)
        *m = mm;
    return sumsq(r ? r : rr, mm);
}

typedef struct nm_user {
    run *R;
    double best_f, best_x[PD_DESIGN_MAX_CHANGES], best_p[MAX_TARGETS];
} nm_user;

/* Nelder-Mead's objective: the drops' at x clamped into the box, plus the
 * squared distance outside it, so that the simplex comes back. */
static double nm_fn(const double *x, void *user)
{
    nm_user *u = user;
    run *R = u->R;
    double y[PD_DESIGN_MAX_CHANGES], pt[MAX_TARGETS], out = 0.0;
    for (int k = 0; k < R->d; k++) {
        y[k] = fmin(1.0, fmax(0.0, x[k]));
        out += (x[k] - y[k]) * (x[k] - y[k]);
    }
    R->drop_evals++;
    double f = drop_eval(R, y, R->o->sim.ndrops, R->o->sim.seed, pt, NULL, NULL, NULL);
    if (R->st != PD_OK || R->partial)
        return NAN; /* stops the simplex */
    if (!isfinite(f))
        f = 4.0;
    if (f < u->best_f) {
        u->best_f = f;
        memcpy(u->best_x, y, sizeof y);
        memcpy(u->best_p, pt, sizeof pt);
    }
    progress(R, "drops", R->drop_evals, u->best_f);
    return f + out;
}

/* Where the drops' search stops: a quarter of the objective that their
 * sampling error gives at the answer, sum_t p_t (1 - p_t) / n, so that each
 * residual is within about half a standard error of its own drops; at the
 * full floor the answer still carried about one standard error of misfit
 * beside the drops' own error, and fresh drops see both. */
static double noise_floor(const run *R, const double *p)
{
    double v = 0.0;
    for (int t = 0; t < R->nt; t++)
        v += p[t] * (1.0 - p[t]);
    return 0.25 * v / (double)R->o->sim.ndrops;
}

/* Stage 3 from x (overwritten by the best point the drops found); the
 * drops' objective there, and the targets' probabilities into best_p. J0
 * is the static Jacobian at x. */
static double drop_stage(run *R, double *x, const double *J0, int m, double *best_p)
{
    int d = R->d;
    double pt[MAX_TARGETS], r[MAX_TARGETS];
    if (R->goal == PD_GOAL_MAXIMISE) {
        /* The static model can be far from the drops (a flange's share
         * under PQS is a fifth of the drops'), so the simplex starts from
         * the best on drops of the static optimum, the range's middle and,
         * for up to three changes, its corners; its first steps span a
         * quarter of the range. */
        nm_user u = {R, HUGE_VAL, {0}, {0}};
        double step[PD_DESIGN_MAX_CHANGES], fmin, y[PD_DESIGN_MAX_CHANGES];
        nm_fn(x, &u);
        int ncorners = d <= 3 ? 1 << d : 0;
        for (int c = -1; c < ncorners && R->st == PD_OK && !R->partial &&
                         R->drop_evals < R->o->max_evals; c++) {
            for (int k = 0; k < d; k++)
                y[k] = c < 0 ? 0.5 : (c >> k) & 1;
            nm_fn(y, &u);
        }
        if (R->st != PD_OK || R->partial || !isfinite(u.best_f))
            return u.best_f;
        memcpy(x, u.best_x, sizeof(double) * (size_t)d);
        for (int k = 0; k < d; k++)
            step[k] = x[k] > 0.5 ? -0.25 : 0.25;
        int evals = 0, left = R->o->max_evals - R->drop_evals;
        pd_status st = left > d ? pd_gsl_nelder_mead(nm_fn, &u, d, x, step, 1e-3, left, &evals,
                                                     &fmin)
                                : PD_OK;
        /* A stop asked for by nm_fn, or a first simplex that could not be
         * set, leaves the best point found; only memory is fatal. */
        if (st == PD_ERR_NOMEM && R->st == PD_OK)
            R->st = pd_fail(R->diag, st, "design: out of memory");
        if (isfinite(u.best_f))
            memcpy(x, u.best_x, sizeof(double) * (size_t)d);
        memcpy(best_p, u.best_p, sizeof u.best_p);
        return u.best_f;
    }
    /* Broyden: J holds the static Jacobian at first, corrected by each
     * step's observed change of the drops' residuals. */
    double J[MAX_TARGETS * PD_DESIGN_MAX_CHANGES];
    memcpy(J, J0, sizeof(double) * (size_t)(m * d));
    R->drop_evals++;
    double f = drop_eval(R, x, R->o->sim.ndrops, R->o->sim.seed, pt, NULL, r, &m);
    memcpy(best_p, pt, sizeof pt);
    progress(R, "drops", R->drop_evals, f);
    double lambda = 1e-6;
    int misses = 0;
    /* Three steps in a row that do not lower the objective, or an
     * objective below noise_floor: the drops' answer is as good as their
     * resolution lets it be. */
    while (R->drop_evals < R->o->max_evals && isfinite(f) && f > noise_floor(R, best_p) &&
           R->st == PD_OK && !R->partial && misses < 3) {
        double x1[PD_DESIGN_MAX_CHANGES], r1[MAX_TARGETS], dx[PD_DESIGN_MAX_CHANGES];
        lm_step(x, r, J, m, d, lambda, x1);
        double dd = 0.0;
        for (int k = 0; k < d; k++) {
            dx[k] = x1[k] - x[k];
            dd += dx[k] * dx[k];
        }
        if (dd < 1e-14)
            break;
        R->drop_evals++;
        double f1 = drop_eval(R, x1, R->o->sim.ndrops, R->o->sim.seed, pt, NULL, r1, &m);
        if (R->partial)
            break; /* a cancelled evaluation's drops are fewer: not comparable */
        if (!isfinite(f1)) {
            lambda = lambda * 10.0 + 1e-3;
            continue;
        }
        for (int t = 0; t < m; t++) {
            double pred = 0.0;
            for (int k = 0; k < d; k++)
                pred += J[t * d + k] * dx[k];
            double miss = (r1[t] - r[t] - pred) / dd;
            for (int k = 0; k < d; k++)
                J[t * d + k] += miss * dx[k];
        }
        if (f1 < f) {
            memcpy(x, x1, sizeof x1[0] * (size_t)d);
            memcpy(r, r1, sizeof r1[0] * (size_t)m);
            memcpy(best_p, pt, sizeof pt);
            f = f1;
            lambda = fmax(lambda / 3.0, 1e-9);
            misses = 0;
        } else {
            lambda = lambda * 4.0 + 1e-4;
            misses++;
        }
        progress(R, "drops", R->drop_evals, f);
    }
    return f;
}

static pd_status check_args(const pd_part *part, const pd_change *changes, int nchanges,
                            pd_design_goal goal, const pd_design_target *targets, int nt,
                            const pd_design_options *o, pd_design_result **result, pd_diag *diag)
{
    if (!part || !changes || !targets || !o || !result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: NULL argument");
    if (nchanges < 1 || nchanges > PD_DESIGN_MAX_CHANGES)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: %d changes: expected 1 to %d",
                       nchanges, PD_DESIGN_MAX_CHANGES);
    if ((unsigned)goal > (unsigned)PD_GOAL_EQUALISE)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: goal %d is none of target, maximise, "
                       "equalise", (int)goal);
    if (nt < (goal == PD_GOAL_EQUALISE ? 2 : 1) || nt > MAX_TARGETS)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: %d poses named: expected %d to %d", nt,
                       goal == PD_GOAL_EQUALISE ? 2 : 1, MAX_TARGETS);
    for (int t = 0; t < nt; t++)
        if (!v3_isfinite(targets[t].normal) || v3_norm(targets[t].normal) == 0.0 ||
            (goal == PD_GOAL_TARGET && !(targets[t].p >= 0.0 && targets[t].p <= 1.0)))
            return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: target %d: expected a nonzero "
                           "normal%s", t + 1, goal == PD_GOAL_TARGET ? " and p from 0 to 1" : "");
    if ((unsigned)o->model > (unsigned)PD_DESIGN_PQS || (o->group != 0 && o->group != 1) ||
        o->max_evals < 1 || o->check_drops < 0 || o->sim.ndrops < 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: options: model %d, group %d, "
                       "max_evals %d, check_drops %ld, ndrops %ld out of range", (int)o->model,
                       o->group, o->max_evals, o->check_drops, o->sim.ndrops);
    if (o->statics.band == PD_PQS_BAND_EXACT && o->statics.epsilon > 0.0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_run: the exact PQS band is a quadrature "
                       "and is not differentiated; use the rect band");
    pd_status st = pd_static_options_check(&o->statics, diag);
    if (st == PD_OK && (o->sim.ndrops > 0 || o->check_drops > 0))
        st = pd_sim_options_check(&o->sim, diag);
    if (st == PD_OK && (o->sim.ndrops > 0 || o->check_drops > 0))
        st = pd_scene_check(&o->scene, diag);
    return st;
}

/* Names each target's facet on the base, refusing a normal no facet has
 * and two targets of one pose (or class). */
static pd_status name_targets(run *R, const pd_design_target *targets, pd_diag *diag)
{
    for (int t = 0; t < R->nt; t++) {
        double angle;
        pd_vec3 n = v3_unit(targets[t].normal);
        R->facet[t] = design_facet_by_normal(R->ctx.base, n, &angle);
        R->target[t] = targets[t].p;
        if (R->facet[t] < 0)
            return pd_fail(diag, PD_ERR_USAGE, "design: target %d's normal (%g, %g, %g): no facet "
                           "of the part's hull within 5 degrees (the nearest is %.3g degrees off)",
                           t + 1, n.x, n.y, n.z, angle * 180.0 / M_PI);
        for (int u = 0; u < t; u++)
            if (R->facet[u] == R->facet[t])
                return pd_fail(diag, PD_ERR_USAGE, "design: targets %d and %d name the same "
                               "facet", u + 1, t + 1);
    }
    return PD_OK;
}

/* The targets' QS and PQS at value (zeros where no part is built). */
static void static_pair(run *R, const double *value, double *qs, double *pqs, int *nposes,
                        int *stable)
{
    point p;
    if (point_at(R, value, &p) != PD_OK) {
        for (int t = 0; t < R->nt; t++)
            qs[t] = pqs[t] = 0.0, stable[t] = 0;
        return;
    }
    static_p(R, &p, 0, qs);
    static_p(R, &p, 1, pqs);
    *nposes = p.res->nposes;
    int np = p.res->nposes;
    for (int t = 0; t < R->nt; t++) {
        stable[t] = 0;
        int g = design_match_facet(R->ctx.base, R->facet[t], p.part, R->mark);
        for (int j = 0; g >= 0 && j < np; j++)
            stable[t] |= p.res->poses[j].facet == g;
    }
    point_free(&p);
}

/* With classes, two targets may name one class of a changed part (a
 * cube's six faces are one class, its flattened box's caps another): the
 * goal then asks one probability twice. PD_ERR_USAGE naming them. */
static pd_status targets_apart(run *R, const double *value, pd_diag *diag)
{
    point p;
    if (point_at(R, value, &p) != PD_OK)
        return R->st;
    int np = p.res->nposes;
    pd_status st = PD_OK;
    for (int t = 0; t < R->nt && st == PD_OK; t++)
        for (int u = 0; u < t && st == PD_OK; u++)
            for (int j = 0; j < np; j++)
                if (p.member[t * np + j] && p.member[u * np + j]) {
                    st = pd_fail(diag, PD_ERR_USAGE, "design: targets %d and %d name one pose "
                                 "class of the changed part: name each class once", u + 1, t + 1);
                    break;
                }
    point_free(&p);
    return st;
}

pd_status pd_design_run(const pd_part *part, const pd_change *changes, int nchanges,
                        pd_design_goal goal, const pd_design_target *targets, int ntargets,
                        const pd_design_options *options, pd_design_result **result,
                        pd_diag *diag)
{
    pd_status st = check_args(part, changes, nchanges, goal, targets, ntargets, options, result,
                              diag);
    if (st != PD_OK)
        return st;
    run R;
    memset(&R, 0, sizeof R);
    if ((st = design_ctx_init(&R.ctx, part, changes, nchanges, diag)) != PD_OK)
        return st;
    R.o = options;
    R.goal = goal;
    R.nt = ntargets;
    R.d = nchanges;
    R.diag = diag;
    if ((st = name_targets(&R, targets, diag)) != PD_OK)
        return st;
    pd_design_result *res = calloc(1, sizeof *res);
    R.mark = calloc((size_t)part->mesh->nverts, sizeof *R.mark);
    if (res)
        res->targets = calloc((size_t)ntargets, sizeof *res->targets);
    if (!res || !R.mark || !res->targets) {
        free(R.mark);
        pd_design_result_free(res);
        return pd_fail(diag, PD_ERR_NOMEM, "design: out of memory");
    }
    res->nchanges = nchanges;
    res->ntargets = ntargets;
    double x0[PD_DESIGN_MAX_CHANGES], x[PD_DESIGN_MAX_CHANGES];
    for (int k = 0; k < nchanges; k++) {
        double id = design_identity(&changes[k]);
        double u = changes[k].kind == PD_CHANGE_SCALE ? log(id) : id;
        x0[k] = fmin(1.0, fmax(0.0, (u - R.ctx.lo[k]) / (R.ctx.hi[k] - R.ctx.lo[k])));
        res->value_before[k] = id;
    }
    double qs[MAX_TARGETS], pqs[MAX_TARGETS];
    int stable[MAX_TARGETS];
    static_pair(&R, res->value_before, qs, pqs, &res->poses_before, stable);
    for (int t = 0; t < ntargets; t++) {
        res->targets[t].qs_before = qs[t];
        res->targets[t].pqs_before = pqs[t];
        res->targets[t].appeared = !stable[t];
    }

    memcpy(x, x0, sizeof x);
    res->objective_static = static_stage(&R, x0, x);
    values_of(&R, x, res->value_static);
    if (R.st == PD_OK && !isfinite(res->objective_static))
        R.st = pd_fail(diag, PD_ERR_RANGE, "design: no value in the ranges gives a part (every "
                       "centre of mass tried lies outside it)");
    if (R.st == PD_OK && options->group)
        R.st = targets_apart(&R, res->value_static, diag);
    if (R.st == PD_OK && options->sim.ndrops > 0) {
        double r[MAX_TARGETS], J[MAX_TARGETS * PD_DESIGN_MAX_CHANGES];
        int m = 0;
        static_eval(&R, x, r, J, &m);
        double pt[MAX_TARGETS];
        res->objective_refine = drop_stage(&R, x, J, m, pt);
        for (int t = 0; t < ntargets; t++)
            res->targets[t].p_refine = pt[t];
    }
    values_of(&R, x, res->value);
    if (R.st == PD_OK) {
        static_pair(&R, res->value_static, qs, pqs, &res->poses_after, stable);
        for (int t = 0; t < ntargets; t++) {
            res->targets[t].qs_static = qs[t];
            res->targets[t].pqs_static = pqs[t];
        }
        static_pair(&R, res->value, qs, pqs, &res->poses_after, stable);
        for (int t = 0; t < ntargets; t++) {
            res->targets[t].qs_after = qs[t];
            res->targets[t].pqs_after = pqs[t];
            res->targets[t].vanished = !stable[t];
        }
    }
    if (R.st == PD_OK && options->check_drops > 0 && !R.partial) {
        double pt[MAX_TARGETS], r[MAX_TARGETS];
        long count[MAX_TARGETS];
        int m;
        res->objective_after = drop_eval(&R, x, options->check_drops, options->check_seed, pt,
                                         count, r, &m);
        for (int t = 0; t < ntargets; t++) {
            res->targets[t].p_after = pt[t];
            pd_wilson(count[t], options->check_drops, PD_Z95, &res->targets[t].lo,
                      &res->targets[t].hi);
        }
        progress(&R, "check", 1, res->objective_after);
    }
    double mean = 0.0;
    for (int t = 0; t < ntargets; t++)
        mean += res->targets[t].p_after / ntargets;
    for (int t = 0; t < ntargets; t++)
        res->targets[t].p_target = goal == PD_GOAL_TARGET ? targets[t].p
                                   : goal == PD_GOAL_EQUALISE ? mean : 1.0;
    point p;
    if (R.st == PD_OK && point_at(&R, res->value, &p) == PD_OK) {
        res->part = p.part;
        p.part = NULL;
        for (int t = 0; t < ntargets; t++) {
            int g = design_match_facet(part, R.facet[t], res->part, R.mark);
            res->targets[t].normal_after = g >= 0 ? res->part->hull->normal[g] : v3(0, 0, 0);
        }
        point_free(&p);
    } else if (R.st == PD_OK) {
        R.st = pd_fail(diag, PD_ERR_INTERNAL, "design: the result's part could not be rebuilt");
    }
    res->static_evals = R.static_evals;
    res->drop_evals = R.drop_evals;
    res->drops = R.drops;
    res->partial = R.partial;
    free(R.mark);
    if (R.st != PD_OK) {
        pd_design_result_free(res);
        return R.st;
    }
    *result = res;
    return PD_OK;
}
