/* fit_engine.c: the search for the maximum of the simulated likelihood and
 * the likelihood weighting around it (docs/calibration.md).
 *
 * The parameters live in the unit cube z (z = (theta - lo) / (hi - lo)), the
 * prior is uniform there, and the simplex searches u = logit(z), so every
 * point it tries is inside the box and no step is wasted on a bound. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/gsl_adapter.h"
#include "fit/fit_engine.h"
#include "posedrop/fit.h"

enum {
    MIN_ROUNDS = 3,       /* weighting rounds: the whole box, then at least two around the maximum */
    MAX_ROUNDS = 6,       /* ... and more, each narrower, while the weight sits on fewer
                             effective points than a round has (a likelihood of thousands
                             of drops is far narrower than the box) */
    DESIGN_PER_PARAM = 4, /* the search's starting design: 4 d + 1 points */
};
/* The simplex stops when its size in u is below this: 0.02 in u is 0.005 of
 * the range at the middle of the box, below what a few hundred measured
 * drops can tell apart. */
static const double SIMPLEX_TOL = 0.02;
/* The first simplex's steps in u: a quarter of the range at the middle. */
static const double SIMPLEX_STEP = 1.0;
/* A later round's box: the maximum plus or minus this many weighted standard
 * deviations of the points so far (a normal's mass beyond 3.5 sd is 5e-4),
 * shrinking at most 4-fold a round so that a round whose points all but
 * one weigh nothing still leaves the next one room. */
static const double BOX_SDS = 3.5, BOX_SHRINK = 4.0;
/* The relative discrepancy tau^2 is a variance over m (1 - m), which a
 * Beta of mean m stays below (tau^2 = 1 / (A + 1) for a Dirichlet of
 * concentration A): at 0.9 a class's interval is nearly [0, 1], and a
 * misfit so large says no more. */
static const double MAX_DISCREPANCY = 0.9;
/* u beyond this is z within 1e-9 of a bound: the box's edge. */
static const double U_MAX = 20.0;

typedef struct {
    const fit_problem *pb;
    double *const *p;
    double *nsim;
    double theta[PD_FIT_MAX_PARAMS];
    pd_status st;
    pd_diag *diag;
    int evals;
    const char *stage; /* for fit_problem's note */
    int round;
    fit_level level;
    /* The model's relative discrepancy (the weighting's, once estimated; 0
     * in the search): each part's log-likelihood is divided by the variance
     * it adds to that of the data's and the drops' noise. */
    double tau2;
    /* The simplex's best points so far, best first. */
    int ntop;
    double top_z[FIT_FINALISTS][PD_FIT_MAX_PARAMS], top_l[FIT_FINALISTS];
} ctx;

/* Part i's cells of counts. */
static const int *cells(const fit_problem *pb, int i, int *ncells)
{
    const int *of = pb->cell_of ? pb->cell_of[i] : NULL;
    *ncells = of && pb->ncells ? pb->ncells[i] : pb->k[i];
    return of;
}

static void to_theta(const fit_problem *pb, const double *z, double *theta)
{
    for (int i = 0; i < pb->d; i++)
        theta[i] = pb->lo[i] + (pb->hi[i] - pb->lo[i]) * z[i];
}

/* The Dirichlet-multinomial log-likelihood at z of the parts with counts
 * (docs/calibration.md: it carries the simulation's own error, so that a
 * class reached by one lucky drop gains little). all as the model's. */
static pd_status evaluate(ctx *c, const double *z, int all, double *loglik)
{
    const fit_problem *pb = c->pb;
    to_theta(pb, z, c->theta);
    c->evals++;
    pd_status st = pb->model(pb->user, c->theta, all, c->level, c->p, c->nsim, c->diag);
    if (st != PD_OK)
        return st;
    double l = 0.0, raw = 0.0;
    for (int i = 0; all != 2 && i < pb->nparts; i++)
        if (pb->count[i]) {
            int nc;
            const int *of = cells(pb, i, &nc);
            double li =
                fit_loglik_cells(pb->k[i], of, nc, pb->count[i], c->p[i], c->nsim[i], pb->alpha);
            raw += li;
            if (c->tau2 > 0) {
                long n = 0;
                for (int j = 0; j < nc; j++)
                    n += pb->count[i][j];
                li /= 1.0 + c->tau2 * (double)n * c->nsim[i] / ((double)n + c->nsim[i]);
            }
            l += li;
        }
    *loglik = l;
    /* The note reports the likelihood itself, not the weights' tempered
     * one, so that the stages' figures compare. */
    if (pb->note)
        pb->note(pb->note_user, c->stage, c->round, raw);
    return PD_OK;
}

/* Keeps z among the FIT_FINALISTS best distinct points of the simplex. */
static void keep_top(ctx *c, const double *z, double l)
{
    int d = c->pb->d, n = c->ntop;
    for (int j = 0; j < n; j++)
        if (memcmp(c->top_z[j], z, sizeof *z * (size_t)d) == 0)
            return;
    if (n == FIT_FINALISTS && !(l > c->top_l[n - 1]))
        return;
    int at = n < FIT_FINALISTS ? n++ : n - 1;
    for (; at > 0 && l > c->top_l[at - 1]; at--) {
        memcpy(c->top_z[at], c->top_z[at - 1], sizeof *z * (size_t)d);
        c->top_l[at] = c->top_l[at - 1];
    }
    memcpy(c->top_z[at], z, sizeof *z * (size_t)d);
    c->top_l[at] = l;
    c->ntop = n;
}

static double objective(const double *u, void *user)
{
    ctx *c = user;
    double z[PD_FIT_MAX_PARAMS], l;
    for (int i = 0; i < c->pb->d; i++) {
        double v = u[i] > U_MAX ? U_MAX : u[i] < -U_MAX ? -U_MAX : u[i];
        z[i] = 1.0 / (1.0 + exp(-v));
    }
    c->st = evaluate(c, z, 0, &l);
    if (c->st == PD_OK)
        keep_top(c, z, l);
    return c->st == PD_OK ? -l : HUGE_VAL;
}

/* Per-part buffers of the model's output. */
static double **part_arrays(const fit_problem *pb)
{
    double **p = calloc((size_t)pb->nparts, sizeof *p);
    for (int i = 0; p && i < pb->nparts; i++)
        if (!(p[i] = malloc(sizeof **p * (size_t)(pb->k[i] > 0 ? pb->k[i] : 1)))) {
            for (int j = 0; j < i; j++)
                free(p[j]);
            free(p);
            return NULL;
        }
    return p;
}

static void free_arrays(const fit_problem *pb, double **p)
{
    for (int i = 0; p && i < pb->nparts; i++)
        free(p[i]);
    free(p);
}

pd_status fit_search(const fit_problem *pb, const fit_settings *s, double *theta, double *loglik,
                     int *evals, pd_diag *diag)
{
    double **p = part_arrays(pb), *nsim = malloc(sizeof *nsim * (size_t)pb->nparts);
    if (!p || !nsim) {
        free_arrays(pb, p);
        free(nsim);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the fit");
    }
    ctx c = {.pb = pb, .p = p, .nsim = nsim, .st = PD_OK, .diag = diag, .stage = "design",
             .level = FIT_LEVEL_SEARCH};
    int d = pb->d;
    /* The design: the middle of the box and 4 d Halton points; the search
     * starts from the best, so a maximum away from the middle is not left
     * for a simplex to crawl to. */
    double z[PD_FIT_MAX_PARAMS], zbest[PD_FIT_MAX_PARAMS], best = -HUGE_VAL;
    pd_status st = PD_OK;
    for (int i = 0; st == PD_OK && i <= DESIGN_PER_PARAM * d; i++) {
        double l;
        for (int j = 0; j < d; j++)
            z[j] = i == 0 ? 0.5 : fit_halton(i, j);
        st = evaluate(&c, z, 0, &l);
        if (st == PD_OK && l > best) {
            best = l;
            memcpy(zbest, z, sizeof z[0] * (size_t)d);
        }
    }
    double u[PD_FIT_MAX_PARAMS], step[PD_FIT_MAX_PARAMS], fmin = 0.0;
    int nm_evals = 0;
    for (int j = 0; j < d; j++) {
        u[j] = log(zbest[j] / (1.0 - zbest[j]));
        step[j] = SIMPLEX_STEP;
    }
    c.stage = "search";
    if (st == PD_OK) {
        st = pd_gsl_nelder_mead(objective, &c, d, u, step, SIMPLEX_TOL, s->max_evals, &nm_evals,
                                &fmin);
        if (st == PD_ERR_INTERNAL && c.st != PD_OK)
            st = c.st; /* the model's failure, its message in diag */
        else if (st != PD_OK)
            st = pd_fail(diag, st, "the Nelder-Mead search failed: %s", pd_status_str(st));
    }
    /* The simplex's two best points on the full drops of another seed:
     * on its own drops the simplex ends where their noise happens to favour
     * the counts, and a choice between two points on fresh drops keeps little
     * of that luck (successive halving: Jamieson and Talwalkar 2016, AISTATS,
     * "Non-stochastic best arm identification and hyperparameter
     * optimization"). */
    c.stage = "final";
    c.level = FIT_LEVEL_FULL;
    double lbest = -HUGE_VAL;
    /* The simplex's best last: the likelier winner is then the point a
     * model that remembers its last evaluation has at hand. */
    for (int t = c.ntop - 1; st == PD_OK && t >= 0; t--) {
        double l;
        st = evaluate(&c, c.top_z[t], 0, &l);
        if (st == PD_OK && l > lbest) {
            lbest = l;
            memcpy(zbest, c.top_z[t], sizeof z[0] * (size_t)d);
        }
    }
    (void)fmin;
    if (st == PD_OK && c.ntop == 0) /* a simplex of no evaluation: the design's best */
        st = evaluate(&c, zbest, 0, &lbest);
    if (st == PD_OK) {
        to_theta(pb, zbest, theta);
        *loglik = lbest;
    }
    *evals += c.evals;
    free_arrays(pb, p);
    free(nsim);
    return st;
}

/* Weighted q-quantile of x (n values) with weights w (summing to 1). */
static double weighted_quantile(int n, const double *x, const double *w, double q, int *order)
{
    for (int i = 0; i < n; i++)
        order[i] = i;
    for (int i = 1; i < n; i++) { /* insertion sort: a few hundred points */
        int o = order[i], j = i;
        for (; j > 0 && x[order[j - 1]] > x[o]; j--)
            order[j] = order[j - 1];
        order[j] = o;
    }
    double acc = 0.0;
    for (int i = 0; i < n; i++) {
        acc += w[order[i]];
        if (acc >= q)
            return x[order[i]];
    }
    return x[order[n - 1]];
}

typedef struct {
    double lo[PD_FIT_MAX_PARAMS], hi[PD_FIT_MAX_PARAMS];
    int npoints;
} box;

/* The balance heuristic's weights: each point's likelihood (its log over
 * the dispersion) over the mixture density of the rounds' uniform boxes at
 * that point. */
static void weights(int d, int n, const double *z, const double *lt, const box *b, int nboxes,
                    double *w)
{
    double top = -HUGE_VAL;
    for (int j = 0; j < n; j++)
        top = lt[j] > top ? lt[j] : top;
    double sum = 0.0;
    for (int j = 0; j < n; j++) {
        double q = 0.0;
        for (int r = 0; r < nboxes; r++) {
            int in = 1;
            double vol = 1.0;
            for (int i = 0; i < d; i++) {
                double x = z[(size_t)j * (size_t)d + (size_t)i];
                in &= x >= b[r].lo[i] && x <= b[r].hi[i];
                vol *= b[r].hi[i] - b[r].lo[i];
            }
            if (in)
                q += (double)b[r].npoints / (double)n / vol;
        }
        w[j] = q > 0 ? exp(lt[j] - top) / q : 0.0;
        sum += w[j];
    }
    for (int j = 0; j < n; j++)
        w[j] /= sum;
}

int fit_weigh_max_evals(const fit_settings *s)
{
    return 1 + FIT_REPEATS + (MAX_ROUNDS + FIT_PREDICT_ROUNDS) * s->npoints;
}

/* The resampled points the predicted parts need, given their values at the
 * m points of pick: the averaged probability of a class is a mean over the
 * picks, whose Monte Carlo error (the picks' variance over m) is held to
 * the error one point's own drops leave, p (1 - p) / S: m at least the
 * picks' variance over p (1 - p) / S for every class, at most
 * FIT_PREDICT_ROUNDS s->npoints (what the plan allows). */
static int predict_points(const fit_problem *pb, const fit_settings *s, int m, const int *pick,
                          const double *store, size_t ksum, const double *sims)
{
    double need = 0.0;
    size_t off = 0;
    if (m < 2)
        return m;
    for (int i = 0; i < pb->nparts; off += (size_t)pb->k[i], i++) {
        if (pb->count[i])
            continue;
        for (int cl = 0; cl < pb->k[i]; cl++) {
            double mean = 0.0, var = 0.0, ns = 0.0;
            for (int t = 0; t < m; t++) {
                mean += store[(size_t)pick[t] * ksum + off + (size_t)cl] / m;
                ns += sims[(size_t)pick[t] * (size_t)pb->nparts + (size_t)i] / m;
            }
            for (int t = 0; t < m; t++) {
                double e = store[(size_t)pick[t] * ksum + off + (size_t)cl] - mean;
                var += e * e / (m - 1);
            }
            double own = ns > 0 ? mean * (1.0 - mean) / ns : 0.0;
            if (own > 0 && var / own > need)
                need = var / own;
        }
    }
    int most = FIT_PREDICT_ROUNDS * s->npoints;
    return need >= most ? most : need > m ? (int)ceil(need) : m;
}

/* The weighting's log-likelihoods lt of n points z (d each) with their
 * simulation noise taken out (docs/calibration.md, "The simulation's noise
 * in the weights"): a quadratic in z - zhat fitted by least squares, and
 * each point's value shrunk toward it by the share of the scatter about it
 * that the noise (variance noise_var, measured at zhat) does not explain,
 * the best linear predictor of a point's likelihood from its own noisy value
 * and the surface (kriging with a nugget; the empirical-Bayes shrinkage of
 * Efron and Morris 1975, JASA 70(350)). Without enough points for the
 * quadratic and a residual degree of freedom per one of the noise's, or
 * without noise, the points' own values. *misfit_var receives the scatter's
 * variance beyond the noise, -1 when no quadratic was fitted. */
static pd_status smooth_loglik(int d, int n, const double *z, const double *zhat,
                               const double *lt, double noise_var, double *X, double *out,
                               double *misfit_var)
{
    int p = (d + 1) * (d + 2) / 2;
    memcpy(out, lt, sizeof *out * (size_t)n);
    *misfit_var = -1.0;
    if (!(noise_var > 0) || n - p < FIT_REPEATS - 1)
        return PD_OK;
    for (int j = 0; j < n; j++) {
        double *row = X + (size_t)j * (size_t)p, x[PD_FIT_MAX_PARAMS];
        int c = 0;
        for (int i = 0; i < d; i++)
            x[i] = z[(size_t)j * (size_t)d + (size_t)i] - zhat[i];
        row[c++] = 1.0;
        for (int i = 0; i < d; i++)
            row[c++] = x[i];
        for (int i = 0; i < d; i++)
            for (int k = i; k < d; k++)
                row[c++] = x[i] * x[k];
    }
    double coef[(PD_FIT_MAX_PARAMS + 1) * (PD_FIT_MAX_PARAMS + 2) / 2], rss;
    pd_status st = pd_gsl_least_squares(n, p, X, lt, coef, &rss);
    if (st != PD_OK)
        return st;
    double misfit = rss / (double)(n - p) - noise_var;
    misfit = misfit > 0 ? misfit : 0.0;
    double keep = misfit / (misfit + noise_var);
    for (int j = 0; j < n; j++) {
        double q = 0.0;
        for (int c = 0; c < p; c++)
            q += coef[c] * X[(size_t)j * (size_t)p + (size_t)c];
        out[j] = q + keep * (lt[j] - q);
    }
    *misfit_var = misfit;
    return PD_OK;
}

/* Systematic resampling: m indices of n points drawn in proportion to w
 * (summing to 1), ascending, with the fixed offset 1/2 (a deterministic
 * draw, whose counts are within one of m w_j for every point). */
static void resample(int n, const double *w, int m, int *pick)
{
    double acc = 0.0;
    int j = 0;
    for (int i = 0; i < m; i++) {
        double u = ((double)i + 0.5) / (double)m;
        while (j < n - 1 && acc + w[j] < u)
            acc += w[j++];
        pick[i] = j;
    }
}

pd_status fit_weigh(const fit_problem *pb, const fit_settings *s, const double *theta,
                    fit_weighed *out, int *evals, pd_diag *diag)
{
    int d = pb->d, np = pb->nparts, total = MAX_ROUNDS * s->npoints, npred = 0;
    size_t ksum = 0;
    for (int i = 0; i < np; i++) {
        ksum += (size_t)pb->k[i];
        npred += !pb->count[i];
    }
    double **p = part_arrays(pb), *nsim = malloc(sizeof *nsim * (size_t)np);
    double *z = malloc(sizeof *z * (size_t)total * (size_t)d);
    double *lt = malloc(sizeof *lt * (size_t)total), *w = malloc(sizeof *w * (size_t)total);
    double *ls = malloc(sizeof *ls * (size_t)total);
    double *X = malloc(sizeof *X * (size_t)total * (size_t)((d + 1) * (d + 2) / 2));
    double *store = malloc(sizeof *store * (size_t)total * ksum);
    double *sims = malloc(sizeof *sims * (size_t)total * (size_t)np);
    double *x = malloc(sizeof *x * (size_t)total), *a = malloc(sizeof *a * (size_t)total);
    double *bb = malloc(sizeof *bb * (size_t)total), *wp = malloc(sizeof *wp * (size_t)total);
    int *order = malloc(sizeof *order * (size_t)total);
    int *pick =
        malloc(sizeof *pick * (size_t)(s->npoints > 0 ? FIT_PREDICT_ROUNDS * s->npoints : 1));
    int *have = calloc((size_t)total, sizeof *have);
    ctx c = {.pb = pb, .p = p, .nsim = nsim, .st = PD_OK, .diag = diag, .stage = "weighting",
             .level = FIT_LEVEL_FULL};
    pd_status st = PD_OK;
    if (!p || !nsim || !z || !lt || !ls || !X || !w || !store || !sims || !x || !a || !bb || !wp ||
        !order || !pick || !have)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the fit's weighting");
    double zhat[PD_FIT_MAX_PARAMS], l;
    for (int i = 0; i < d; i++)
        zhat[i] = (theta[i] - pb->lo[i]) / (pb->hi[i] - pb->lo[i]);
    if (st == PD_OK)
        st = evaluate(&c, zhat, 1, &l);
    if (st == PD_OK) {
        for (int i = 0; i < np; i++) {
            pd_fit_smooth(pb->k[i], p[i], nsim[i], pb->alpha, out->p_best[i]);
            out->nsim_best[i] = nsim[i];
        }
        /* Overdispersion: X^2 beyond what the data's and the simulation's
         * noise explain is the model's own misfit. X^2 of the 2 x K table
         * of counts and simulated drops, whose terms stay of order 1 where
         * the drops reached a class rarely: against the smoothed
         * probabilities, a class of many counts and no drop gave terms of
         * hundreds (expected counts near alpha n / nsim). The excess is
         * read as a scatter of every part's true probabilities about the
         * model's, of variance tau^2 p (1 - p), added to the noise's p (1 -
         * p)(1 / n + 1 / nsim): the fitted parameters take their share
         * df / (df + d) of both. */
        double x2 = 0.0, expect = 0.0, spread = 0.0;
        int df = -d;
        for (int i = 0; i < np; i++) {
            if (!pb->count[i])
                continue;
            long n = 0;
            int nc, dfi;
            const int *of = cells(pb, i, &nc);
            for (int j = 0; j < nc; j++)
                n += pb->count[i][j];
            x2 += fit_chi2_two_sample(pb->k[i], of, nc, pb->count[i], p[i], nsim[i], &dfi);
            expect += dfi;
            /* What a relative discrepancy tau^2 adds to the part's
             * expected X^2: tau^2 dfi n nsim / (n + nsim). */
            spread += dfi * (double)n * nsim[i] / ((double)n + nsim[i]);
            df += dfi;
        }
        /* Without a degree of freedom left, X^2 says nothing of the fit. */
        double share = df > 0 ? (double)df / (double)(df + d) : 0.0;
        expect *= share;
        spread *= share;
        out->dispersion = df > 0 && x2 > expect ? x2 / expect : 1.0;
        out->discrepancy = df > 0 && x2 > expect && spread > 0 ? (x2 - expect) / spread : 0.0;
        if (out->discrepancy > MAX_DISCREPANCY)
            out->discrepancy = MAX_DISCREPANCY;
        /* The weights' likelihood counts the discrepancy beside the noise
         * of the points' own drops (quasi-likelihood, the variance scaled
         * part by part): at the drops X^2 was measured on, the division
         * by the dispersion; at the weighting's fewer drops, whose own
         * noise the Dirichlet-multinomial already counts, less. */
        c.tau2 = out->discrepancy;
    }
    /* The weighting's likelihood at the maximum on FIT_REPEATS sets of
     * drops of its own: its spread is the simulation's noise at every
     * point, which with S/4 drops a part measured a standard deviation of
     * 3 to 4 against a range of 17 over the whole box in the paper's
     * leave-one-out folds, enough to put the weight on the two or three
     * points whose drops happened to favour the counts. */
    double rep[FIT_REPEATS], noise_var = 0.0, misfit_var = -1.0;
    c.stage = "repeat";
    for (int r = 0; st == PD_OK && r < FIT_REPEATS; r++) {
        c.level = (fit_level)(FIT_LEVEL_REPEAT + r);
        st = evaluate(&c, zhat, 0, &rep[r]);
    }
    if (st == PD_OK) {
        /* About the first repeat, so that equal repeats (a model without
         * noise) give exactly 0. */
        double s1 = 0.0, s2 = 0.0;
        for (int r = 1; r < FIT_REPEATS; r++) {
            s1 += rep[r] - rep[0];
            s2 += (rep[r] - rep[0]) * (rep[r] - rep[0]);
        }
        noise_var = (s2 - s1 * s1 / FIT_REPEATS) / (FIT_REPEATS - 1);
        noise_var = noise_var > 0 ? noise_var : 0.0;
    }
    c.stage = "weighting";
    box b[MAX_ROUNDS];
    double half[PD_FIT_MAX_PARAMS];
    int n = 0;
    long index = 1;
    double ess = 0.0;
    for (int r = 0; st == PD_OK && r < MAX_ROUNDS; r++) {
        if (r >= MIN_ROUNDS && ess >= s->npoints)
            break;
        c.round = r + 1;
        for (int i = 0; i < d; i++) {
            if (r == 0) {
                half[i] = 0.5;
                b[r].lo[i] = 0.0;
                b[r].hi[i] = 1.0;
                continue;
            }
            /* The weighted mean and spread of the points so far decide the
             * next box (adaptive importance sampling: the proposal moved to
             * the weighted sample's moments, Cappé, Guillin, Marin and Robert
             * 2004, J. Comput. Graph. Stat. 13(4), "Population Monte
             * Carlo"). Not centred on the search's maximum: with the
             * simulation's noise that is one lucky point, and a posterior
             * whose mass lies beside it would be left to the whole box's
             * few points, each carrying a large share of the weight. */
            double m = 0.0, v = 0.0;
            for (int j = 0; j < n; j++)
                m += w[j] * z[(size_t)j * (size_t)d + (size_t)i];
            for (int j = 0; j < n; j++) {
                double e = z[(size_t)j * (size_t)d + (size_t)i] - m;
                v += w[j] * e * e;
            }
            double h = BOX_SDS * sqrt(v);
            h = h < half[i] / BOX_SHRINK ? half[i] / BOX_SHRINK : h > half[i] ? half[i] : h;
            half[i] = h;
            b[r].lo[i] = m - h < 0 ? 0.0 : m - h;
            b[r].hi[i] = m + h > 1 ? 1.0 : m + h;
        }
        b[r].npoints = s->npoints;
        c.level = FIT_LEVEL_WEIGH;
        for (int j = 0; st == PD_OK && j < s->npoints; j++, n++, index++) {
            double *zj = z + (size_t)n * (size_t)d;
            for (int i = 0; i < d; i++)
                zj[i] = b[r].lo[i] + (b[r].hi[i] - b[r].lo[i]) * fit_halton(index, i);
            st = evaluate(&c, zj, 0, &lt[n]);
            double *sj = store + (size_t)n * ksum;
            for (int i = 0; st == PD_OK && i < np; i++) {
                memcpy(sj, p[i], sizeof *sj * (size_t)pb->k[i]);
                sj += pb->k[i];
                sims[(size_t)n * (size_t)np + (size_t)i] = nsim[i];
            }
        }
        if (st == PD_OK)
            st = smooth_loglik(d, n, z, zhat, lt, noise_var, X, ls, &misfit_var);
        if (st == PD_OK) {
            weights(d, n, z, ls, b, r + 1, w);
            double sw2 = 0.0;
            for (int j = 0; j < n; j++)
                sw2 += w[j] * w[j];
            ess = 1.0 / sw2;
        }
    }
    /* The parts without counts do not move the weights: they are simulated
     * only at some of the points, drawn by weight, each standing for its
     * share (an unbiased estimate of their weighted mixture): s->npoints
     * first, then as many as their Monte Carlo error asks, up to
     * FIT_PREDICT_ROUNDS times that (predict_points). */
    for (int j = 0; j < n; j++)
        wp[j] = 0.0;
    int mpred = s->npoints;
    for (int pass = 0; st == PD_OK && npred > 0 && pass < 2; pass++) {
        resample(n, w, mpred, pick);
        c.stage = "prediction";
        c.round = 0;
        c.level = FIT_LEVEL_FULL;
        for (int j = 0; j < n; j++)
            wp[j] = 0.0;
        for (int t = 0; st == PD_OK && t < mpred; t++) {
            int j = pick[t];
            wp[j] += 1.0 / (double)mpred;
            if (have[j])
                continue;
            have[j] = 1;
            st = evaluate(&c, z + (size_t)j * (size_t)d, 2, &l);
            size_t off = 0;
            for (int i = 0; st == PD_OK && i < np; off += (size_t)pb->k[i], i++) {
                if (pb->count[i])
                    continue;
                memcpy(store + (size_t)j * ksum + off, p[i], sizeof *store * (size_t)pb->k[i]);
                sims[(size_t)j * (size_t)np + (size_t)i] = nsim[i];
            }
        }
        if (st == PD_OK && pass == 0)
            mpred = predict_points(pb, s, mpred, pick, store, ksum, sims);
        if (mpred <= s->npoints)
            break;
    }
    if (st == PD_OK) {
        out->ess = ess;
        out->npoints = n;
        out->noise_sd = sqrt(noise_var);
        out->misfit_sd = misfit_var >= 0 ? sqrt(misfit_var) : -1.0;
        for (int i = 0; i < d; i++) {
            double m = 0.0;
            for (int j = 0; j < n; j++) {
                x[j] = z[(size_t)j * (size_t)d + (size_t)i];
                m += w[j] * x[j];
            }
            double span = pb->hi[i] - pb->lo[i];
            double qlo = weighted_quantile(n, x, w, 0.025, order);
            double qhi = weighted_quantile(n, x, w, 0.975, order);
            /* The best value is one the data allow: with a skewed
             * likelihood, or the weight on few points, the central 95%
             * can miss it, and the interval is then stretched to it. */
            qlo = zhat[i] < qlo ? zhat[i] : qlo;
            qhi = zhat[i] > qhi ? zhat[i] : qhi;
            out->mean[i] = pb->lo[i] + span * m;
            out->lo[i] = pb->lo[i] + span * qlo;
            out->hi[i] = pb->lo[i] + span * qhi;
        }
        /* Each point's probability of a class is known to within its own
         * drops' error: the posterior Beta of that class under the
         * Dirichlet(alpha) prior. The averaged prediction is the mixture of
         * those Betas with the likelihood weights. */
        size_t off = 0;
        for (int i = 0; i < np; i++) {
            int k = pb->k[i];
            const double *wi = pb->count[i] ? w : wp;
            for (int cl = 0; cl < k; cl++) {
                double mean = 0.0;
                for (int j = 0; j < n; j++) {
                    if (!(wi[j] > 0)) {
                        a[j] = bb[j] = 1.0; /* weightless: never read */
                        continue;
                    }
                    double ns = sims[(size_t)j * (size_t)np + (size_t)i];
                    double pj = store[(size_t)j * ksum + off + (size_t)cl];
                    a[j] = ns * pj + pb->alpha;
                    bb[j] = ns * (1.0 - pj) + (double)(k - 1) * pb->alpha;
                    if (bb[j] < pb->alpha) /* round-off of 1 - pj */
                        bb[j] = pb->alpha;
                    mean += wi[j] * a[j] / (a[j] + bb[j]);
                }
                out->p[i][cl] = mean;
                out->plo[i][cl] = fit_beta_mixture_quantile(n, wi, a, bb, 0.025);
                out->phi[i][cl] = fit_beta_mixture_quantile(n, wi, a, bb, 0.975);
                if (out->plo_fit) {
                    out->plo_fit[i][cl] = out->plo[i][cl];
                    out->phi_fit[i][cl] = out->phi[i][cl];
                }
                if (pb->count[i] || !(out->discrepancy > 0))
                    continue;
                /* A predicted part's true probability scatters about the
                 * model's as the fitted parts' do: at each point, the Beta
                 * of the same mean whose variance adds tau^2 m (1 - m)
                 * to what the drops leave open (their compound's variance,
                 * matched). */
                for (int j = 0; j < n; j++) {
                    if (!(wi[j] > 0))
                        continue;
                    double sj = a[j] + bb[j], mj = a[j] / sj;
                    double v = mj * (1.0 - mj) / (sj + 1.0);
                    v = v * (1.0 - out->discrepancy) + out->discrepancy * mj * (1.0 - mj);
                    sj = mj * (1.0 - mj) / v - 1.0;
                    a[j] = mj * sj;
                    bb[j] = (1.0 - mj) * sj;
                }
                /* A class of mean below 0.025 can have its 97.5% quantile
                 * fall as the scatter grows (the Beta tends to a coin of 0
                 * and 1): the interval keeps the drops' at least. */
                double lo = fit_beta_mixture_quantile(n, wi, a, bb, 0.025);
                double hi = fit_beta_mixture_quantile(n, wi, a, bb, 0.975);
                out->plo[i][cl] = lo < out->plo[i][cl] ? lo : out->plo[i][cl];
                out->phi[i][cl] = hi > out->phi[i][cl] ? hi : out->phi[i][cl];
            }
            off += (size_t)k;
        }
    }
    *evals += c.evals;
    free_arrays(pb, p);
    free(nsim);
    free(z);
    free(lt);
    free(ls);
    free(X);
    free(w);
    free(store);
    free(sims);
    free(x);
    free(a);
    free(bb);
    free(wp);
    free(order);
    free(pick);
    free(have);
    return st;
}
