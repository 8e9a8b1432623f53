/* test_fit.c: the calibration (posedrop/fit.h): the smoothed likelihood on
 * hand-computed cases, the search and the weighting on models whose answer
 * is a closed form, the intervals' coverage over repeats of a simulated
 * model with common random numbers, and the recovery of a scene value from
 * posedrop's own drops. The runner's --full (make check-full) adds the
 * coverage of the recovery over repeats of posedrop's drops and of held-out
 * predictions with the model right and wrong (minutes, not for every
 * check). */
#include <limits.h>
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "check.h"
#include "cli_run.h"
#include "base/gsl_adapter.h"
#include "fit/fit_engine.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"

/* Round-off of a few logarithms and divisions of numbers of order 1. */
static const double ROUND = 1e-13;

static void test_likelihood_hand(void)
{
    /* 10 simulated drops, 5 and 5 on classes 1 and 3, none on 2; alpha 1/2:
     * (5 + 1/2) / (10 + 3/2) = 11/23 and 1/23. */
    const double p[] = {0.5, 0.0, 0.5};
    double s[3];
    pd_fit_smooth(3, p, 10.0, 0.5, s);
    CHECK_NEAR(s[0], 11.0 / 23.0, ROUND, "hand: 5.5 / 11.5");
    CHECK_NEAR(s[1], 1.0 / 23.0, ROUND, "hand: 0.5 / 11.5");
    CHECK_NEAR(s[0] + s[1] + s[2], 1.0, ROUND, "the smoothed probabilities sum to 1");
    const long c[] = {5, 0, 2};
    CHECK_NEAR(pd_fit_loglik(3, c, p, 10.0, 0.5), 7.0 * log(11.0 / 23.0), ROUND,
               "hand: 5 log(11/23) + 2 log(11/23)");
    /* Measured on the class no drop reached: finite, 3 log(1/23). */
    const long unreached[] = {0, 3, 0};
    double l = pd_fit_loglik(3, unreached, p, 10.0, 0.5);
    CHECK(isfinite(l));
    CHECK_NEAR(l, 3.0 * log(1.0 / 23.0), ROUND, "hand: an unreached class gets alpha / 11.5");
    /* Many simulated drops: the plain multinomial log-likelihood. */
    const double q[] = {0.2, 0.3, 0.5};
    const long c2[] = {1, 2, 3};
    CHECK_NEAR(pd_fit_loglik(3, c2, q, 1e12, 0.5), log(0.2) + 2 * log(0.3) + 3 * log(0.5), 1e-11,
               "alpha / nsim = 5e-13 relative, times 6 counts");
    /* The Dirichlet-multinomial: 2 simulated drops, one on each of classes 1
     * and 3, alpha 1/2: a = (3/2, 1/2, 3/2), A = 7/2; counts 1, 0, 1 give
     * (3/2)(3/2) / ((7/2)(9/2)) = 1/7. */
    const long c11[] = {1, 0, 1};
    CHECK_NEAR(pd_fit_loglik_dm(3, c11, p, 2.0, 0.5), log(1.0 / 7.0), ROUND,
               "hand: Gamma ratios of small half-integers");
    /* Large simulated counts (Stirling's side): the rising factorials as sums
     * of logs, and the plug-in likelihood in the limit. */
    const double pr[] = {0.4, 0.6};
    const long c46[] = {40, 60};
    double direct = 0.0;
    for (int j = 0; j < 40; j++)
        direct += log(400.5 + j);
    for (int j = 0; j < 60; j++)
        direct += log(600.5 + j);
    for (int j = 0; j < 100; j++)
        direct -= log(1001.0 + j);
    CHECK_NEAR(pd_fit_loglik_dm(2, c46, pr, 1000.0, 0.5), direct, 1e-10,
               "200 logs of order 7 summed: round-off 1e-13 each");
    CHECK_NEAR(pd_fit_loglik_dm(2, c46, pr, 1e12, 0.5), 40 * log(0.4) + 60 * log(0.6), 1e-8,
               "the plug-in limit: the DM's excess is of order n^2 / nsim = 1e-8");
    /* Classes 1 and 3 counted as one set: the Dirichlet's sum over them is
     * Beta(s + 2 alpha, ...): a = 3 against A = 7/2, two counts give
     * (3)(4) / ((7/2)(9/2)). */
    const int cell_of[] = {0, 1, 0};
    const long c2set[] = {2, 0};
    CHECK_NEAR(fit_loglik_cells(3, cell_of, 2, c2set, p, 2.0, 0.5), log(12.0 / 15.75), ROUND,
               "hand: the set's Gamma ratio");
    CHECK_NEAR(fit_cell_p(3, cell_of, 0, p), 1.0, ROUND, "the set's probability: 0.5 + 0.5");
    /* X^2 of the set's 2 counts against 2 * 1 expected, the other cell's 0
     * against 0 + ... : (2 - 2)^2 / 2 + (0 - 0.2)^2 / 0.2 with p = (0.4, 0.1, 0.5). */
    const double p415[] = {0.4, 0.1, 0.5};
    CHECK_NEAR(fit_chi2_cells(3, cell_of, 2, c2set, p415), 0.04 / 0.2 + 0.04 / 1.8, ROUND,
               "hand: expected 1.8 and 0.2");
    /* Pearson's X^2: n = 6, expected 1.2, 1.8, 3: 0.04/1.2 + 0.04/1.8 + 0. */
    CHECK_NEAR(fit_chi2(3, c2, q), 0.04 / 1.2 + 0.04 / 1.8, ROUND, "hand");
}

static void test_beta_mixture(void)
{
    const double w1[] = {1.0}, a1[] = {2.0}, b1[] = {1.0};
    /* Beta(2, 1): CDF x^2, so the q-quantile is sqrt(q). */
    CHECK_NEAR(fit_beta_mixture_quantile(1, w1, a1, b1, 0.25), 0.5, 1e-8, "bisection to 1e-9");
    /* Beta(1, 1) and Beta(2, 1), half each: CDF (x + x^2) / 2; at 0.3 it is
     * x = (-1 + sqrt(1 + 2.4)) / 2. */
    const double w2[] = {0.5, 0.5}, a2[] = {1.0, 2.0}, b2[] = {1.0, 1.0};
    CHECK_NEAR(fit_beta_mixture_quantile(2, w2, a2, b2, 0.3), (-1.0 + sqrt(3.4)) / 2.0, 1e-8,
               "bisection to 1e-9");
}

/* A model of closed form: part i has two classes, p = (theta_i, 1 -
 * theta_i), known exactly (nsim so large that the smoothing and the
 * simulation's error vanish). */
static pd_status exact_model(void *user, const double *theta, int all, fit_level level,
                             double *const *p, double *nsim, pd_diag *diag)
{
    const int *nparts = user;
    (void)all;
    (void)level;
    (void)diag;
    for (int i = 0; i < *nparts; i++) {
        p[i][0] = theta[i];
        p[i][1] = 1.0 - theta[i];
        nsim[i] = 1e15;
    }
    return PD_OK;
}

static void test_search_closed_form(void)
{
    /* Binomial counts 40/60 and 25/75: the maximum is (0.4, 0.25). */
    const long c0[] = {40, 60}, c1[] = {25, 75};
    const long *count[] = {c0, c1};
    const int k[] = {2, 2};
    const double lo[] = {0.05, 0.05}, hi[] = {0.95, 0.95};
    int nparts = 2, evals = 0;
    fit_problem pb = {2, lo, hi, 2, k, count, NULL, NULL, 0.5, exact_model, &nparts, NULL, NULL};
    fit_settings s = {200, 32};
    double theta[2], l;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(fit_search(&pb, &s, theta, &l, &evals, &diag), PD_OK);
    /* The simplex stops at size 0.02 in logit space: at most 0.25 * 0.9 * 0.02
     * in theta. */
    CHECK_NEAR(theta[0], 0.4, 0.0045, "the simplex's size tolerance mapped to theta");
    CHECK_NEAR(theta[1], 0.25, 0.0045, "the simplex's size tolerance mapped to theta");
    CHECK_NEAR(l, 40 * log(0.4) + 60 * log(0.6) + 25 * log(0.25) + 75 * log(0.75), 1e-2,
               "the maximum's value: second order in the 0.0045 position error, n = 100 each");
    pd_note("closed-form search: (%.5f, %.5f) in %d evaluations\n", theta[0], theta[1], evals);

    /* The weighting: with a flat prior the weights are the posterior,
     * Beta(41, 61) for theta_0; the interval is its quantiles. */
    double wlo[2], whi[2], wmean[2], pbest0[2], pbest1[2], p0[2], p1[2], plo0[2], plo1[2],
        phi0[2], phi1[2], nsb[2];
    double *pb_best[] = {pbest0, pbest1}, *pp[] = {p0, p1}, *plo[] = {plo0, plo1},
           *phi[] = {phi0, phi1};
    fit_weighed w = {wlo, whi, wmean, pb_best, nsb, pp, plo, phi, 1, 0, 0, 0, NULL, NULL, 0, 0};
    fit_settings s2 = {200, 64};
    CHECK_STATUS(fit_weigh(&pb, &s2, theta, &w, &evals, &diag), PD_OK);
    const double one[] = {1.0}, a[] = {41.0}, b[] = {61.0};
    double qlo = fit_beta_mixture_quantile(1, one, a, b, 0.025);
    double qhi = fit_beta_mixture_quantile(1, one, a, b, 0.975);
    /* The last round's 64 points span about 7 sd (sd 0.048): 0.005 apart. */
    CHECK_NEAR(wlo[0], qlo, 0.01, "two spacings of the last round's points");
    CHECK_NEAR(whi[0], qhi, 0.01, "two spacings of the last round's points");
    CHECK_NEAR(wmean[0], 41.0 / 102.0, 0.005, "the posterior mean; quasi-random integration");
    pd_note("closed-form weighting: [%.4f, %.4f] against Beta's [%.4f, %.4f], ESS %.1f of %d\n",
            wlo[0], whi[0], qlo, qhi, w.ess, w.npoints);
    /* A closed form has no simulation noise: the repeats agree exactly and
     * the points' own likelihoods are used, unsmoothed. */
    CHECK(w.noise_sd == 0.0);
    CHECK(w.misfit_sd == -1.0);
}

/* The least squares behind the weighting's smoothing, against hand
 * values: a line through (0, 0), (1, 1), (2, 0) is 1/3 flat, residuals
 * -1/3, 2/3, -1/3 (sum of squares 2/3); an exact quadratic is recovered. */
static void test_least_squares(void)
{
    const double X1[] = {1, 0, 1, 1, 1, 2}, y1[] = {0, 1, 0};
    double c[3], rss;
    CHECK_STATUS(pd_gsl_least_squares(3, 2, X1, y1, c, &rss), PD_OK);
    CHECK_NEAR(c[0], 1.0 / 3.0, 1e-12, "round-off of an SVD of a 3 x 2 matrix");
    CHECK_NEAR(c[1], 0.0, 1e-12, "round-off");
    CHECK_NEAR(rss, 2.0 / 3.0, 1e-12, "round-off");
    double X2[3 * 6], y2[6];
    for (int i = 0; i < 6; i++) {
        double x = -1.0 + 0.4 * i;
        X2[3 * i] = 1.0;
        X2[3 * i + 1] = x;
        X2[3 * i + 2] = x * x;
        y2[i] = 1.0 + 2.0 * x - 3.0 * x * x;
    }
    CHECK_STATUS(pd_gsl_least_squares(6, 3, X2, y2, c, &rss), PD_OK);
    CHECK_NEAR(c[0], 1.0, 1e-12, "round-off");
    CHECK_NEAR(c[1], 2.0, 1e-12, "round-off");
    CHECK_NEAR(c[2], -3.0, 1e-12, "round-off");
    CHECK_NEAR(rss, 0.0, 1e-20, "round-off squared");
}

/* A model that cannot fit: p = (theta, (1 - theta) / 2, (1 - theta) / 2)
 * against counts 30, 60, 10, known exactly. */
static pd_status misfit_model(void *user, const double *theta, int all, fit_level level,
                              double *const *p, double *nsim, pd_diag *diag)
{
    (void)user;
    (void)level;
    (void)all;
    (void)diag;
    p[0][0] = theta[0];
    p[0][1] = p[0][2] = 0.5 * (1.0 - theta[0]);
    nsim[0] = 1e15;
    return PD_OK;
}

static void test_dispersion(void)
{
    const long c[] = {30, 60, 10};
    const long *count[] = {c};
    const int k[] = {3};
    const double lo[] = {0.05}, hi[] = {0.95};
    fit_problem pb = {1, lo, hi, 1, k, count, NULL, NULL, 0.5, misfit_model, NULL, NULL, NULL};
    fit_settings s = {200, 32};
    double theta[1], l, wlo[1], whi[1], wmean[1], pb0[3], p0[3], l0[3], h0[3], nsb[1];
    double *pbb[] = {pb0}, *pp[] = {p0}, *pl[] = {l0}, *ph[] = {h0};
    fit_weighed w = {wlo, whi, wmean, pbb, nsb, pp, pl, ph, 1, 0, 0, 0, NULL, NULL, 0, 0};
    int evals = 0;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(fit_search(&pb, &s, theta, &l, &evals, &diag), PD_OK);
    CHECK_NEAR(theta[0], 0.3, 0.0045, "the simplex's size tolerance mapped to theta");
    CHECK_STATUS(fit_weigh(&pb, &s, theta, &w, &evals, &diag), PD_OK);
    /* One degree of freedom of two classes' worth of X^2 after one fitted
     * parameter: the noise explains 2 * 1/2 = 1, so the dispersion is X^2
     * itself, about 35.7 at theta = 0.3. */
    const double pt[] = {theta[0], 0.5 * (1 - theta[0]), 0.5 * (1 - theta[0])};
    CHECK_NEAR(w.dispersion, fit_chi2(3, c, pt), 1e-6, "alpha / nsim = 5e-16 relative");
    CHECK(w.dispersion > 30);
    /* The interval is widened by sqrt(35.7) = 6: the plain one (Beta(31, 71)
     * again, 0.19 wide) would be at least 3 times narrower. */
    CHECK(whi[0] - wlo[0] > 3 * 0.19);
    pd_note("dispersion %.2f: interval [%.3f, %.3f]\n", w.dispersion, wlo[0], whi[0]);
}

/* A simulated model with common random numbers: class 0 for the uniforms
 * below theta. Its p is a step function of theta, as posedrop's counts are.
 * As fit.c's drops: 2 S uniforms fixed for the whole fit, the first S the
 * search's seed (a quarter of them for the design and the simplex), the
 * other S the full level's (a quarter of them for the weighting's points),
 * then a quarter of S for each of the weighting's repeats at the maximum. */
typedef struct {
    int S;
    double *u;
} crn_model;

static pd_status crn_sim(void *user, const double *theta, int all, fit_level level,
                         double *const *p, double *nsim, pd_diag *diag)
{
    const crn_model *m = user;
    (void)all;
    (void)diag;
    int n = level == FIT_LEVEL_SEARCH || level == FIT_LEVEL_WEIGH || level >= FIT_LEVEL_REPEAT
                ? m->S / 4
                : m->S;
    const double *u = level >= FIT_LEVEL_REPEAT
                          ? m->u + 2 * m->S + (level - FIT_LEVEL_REPEAT) * (m->S / 4)
                      : level >= FIT_LEVEL_FULL ? m->u + m->S
                                                : m->u;
    int below = 0;
    for (int i = 0; i < n; i++)
        below += u[i] < theta[0];
    p[0][0] = (double)below / n;
    p[0][1] = 1.0 - p[0][0];
    nsim[0] = n;
    return PD_OK;
}

/* Fits theta_true's binomial counts of n drops with S simulated ones; the
 * 95% interval into lo, hi. */
static void crn_fit(test_rng *rng, double truth, long n, int S, double *lo, double *hi,
                    double *best)
{
    int nu = 2 * S + FIT_REPEATS * (S / 4);
    crn_model m = {S, malloc(sizeof(double) * (size_t)nu)};
    for (int i = 0; i < nu; i++)
        m.u[i] = rng_uniform(rng);
    long c[2] = {0, 0};
    for (long i = 0; i < n; i++)
        c[rng_uniform(rng) < truth ? 0 : 1]++;
    const long *count[] = {c};
    const int k[] = {2};
    const double plo_[] = {0.05}, phi_[] = {0.95};
    fit_problem pb = {1, plo_, phi_, 1, k, count, NULL, NULL, 0.5, crn_sim, &m, NULL, NULL};
    fit_settings s = {150, 16};
    double theta[1], l, wmean[1], pb0[2], p0[2], l0[2], h0[2], nsb[1];
    double *pbb[] = {pb0}, *pp[] = {p0}, *pl[] = {l0}, *ph[] = {h0};
    fit_weighed w = {lo, hi, wmean, pbb, nsb, pp, pl, ph, 1, 0, 0, 0, NULL, NULL, 0, 0};
    int evals = 0;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(fit_search(&pb, &s, theta, &l, &evals, &diag), PD_OK);
    CHECK_STATUS(fit_weigh(&pb, &s, theta, &w, &evals, &diag), PD_OK);
    *best = theta[0];
    free(m.u);
}

static void test_coverage_crn(void)
{
    /* 300 measured drops, 300 simulated: the simulation's error is as large
     * as the data's, and intervals that ignored it would cover about 83%
     * (1.96 / sqrt(2) sd). */
    enum { R = 200 };
    const double truth = 0.3;
    test_rng rng = {20261127};
    int covered = 0;
    double width = 0.0;
    for (int r = 0; r < R; r++) {
        double lo, hi, best;
        crn_fit(&rng, truth, 300, 300, &lo, &hi, &best);
        covered += lo <= truth && truth <= hi;
        width += (hi - lo) / R;
    }
    /* At a true rate of 95%, R trials cover at least R 0.95 - 3 sd. */
    double bound = R * 0.95 - 3.0 * sqrt(R * 0.95 * 0.05);
    CHECK(covered >= bound);
    pd_note("CRN coverage: %d of %d (bound %.1f), mean width %.4f\n", covered, R, bound, width);

    /* More data narrows them: 10 times the drops, measured and simulated,
     * divide the width by sqrt(10). */
    double w1 = 0.0, w10 = 0.0;
    enum { RW = 10 };
    for (int r = 0; r < RW; r++) {
        double lo, hi, best;
        crn_fit(&rng, truth, 200, 400, &lo, &hi, &best);
        w1 += hi - lo;
        crn_fit(&rng, truth, 2000, 4000, &lo, &hi, &best);
        w10 += hi - lo;
    }
    CHECK_NEAR(w10 / w1, 1.0 / sqrt(10.0), 0.08,
               "1/sqrt(10); the quantiles' discretisation and 10 repeats' spread");
    pd_note("CRN widths: %.4f at 200 drops, %.4f at 2000: ratio %.3f\n", w1 / RW, w10 / RW, w10 / w1);
}

/* The 1 x 2 x 3 cm box, its pose classes, and counts of n of posedrop's
 * own drops at restitution e (seed 1000 + rep, never the fit's). */
typedef struct {
    pd_part *part;
    pd_static_result *res;
    int *class_of, nclasses;
} box_part;

static int box_make_sized(box_part *b, double ax, double ay, double az);

static int box_make(box_part *b) { return box_make_sized(b, 0.01, 0.02, 0.03); }

static void box_free(box_part *b)
{
    free(b->class_of);
    pd_static_result_free(b->res);
    pd_part_free(b->part);
}

static int scene_classes(const box_part *b, const pd_scene *sc, long n, uint64_t seed,
                         long *count, double *p);

static int box_counts(const box_part *b, double e, long n, uint64_t seed, long *count)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.restitution = e;
    return scene_classes(b, &sc, n, seed, count, NULL);
}

static const pd_fit_param box_e = {"restitution", 0.05, 0.7, 0, 0};

/* The defaults with the fit's size: drops per part and evaluation, the
 * simplex's evaluations and the weighting's points a round. */
static pd_fit_options fit_opts(long nsim, int max_evals, int npoints)
{
    pd_fit_options o;
    pd_fit_options_default(&o);
    o.ndrops = nsim;
    o.max_evals = max_evals;
    o.npoints = npoints;
    return o;
}

static pd_status box_fit(const box_part *b, const long *count, pd_fit_param prm, long nsim,
                         int max_evals, int npoints, pd_fit_result **fr)
{
    pd_fit_part fp = {b->part, b->res, b->class_of, b->nclasses, count, NULL, 0};
    pd_fit_options o = fit_opts(nsim, max_evals, npoints);
    pd_diag diag;
    pd_diag_init(&diag);
    return pd_fit_run(&fp, 1, &prm, 1, NULL, &o, fr, &diag);
}

static void test_recovery(void)
{
    box_part b;
    CHECK(box_make(&b));
    if (!b.class_of) {
        box_free(&b);
        return;
    }
    const double truth = 0.4;
    long count[8];
    CHECK(b.nclasses <= 8);
    CHECK(box_counts(&b, truth, 300, 1000, count));
    pd_fit_result *fr = NULL;
    CHECK_STATUS(box_fit(&b, count, box_e, 500, 40, 8, &fr), PD_OK);
    if (fr) {
        /* A 95% interval holds the truth (one draw: a 95% event, fixed by
         * the seeds); the best value is within 3 of the interval's sds. */
        CHECK(fr->lo[0] <= truth && truth <= fr->hi[0]);
        CHECK_NEAR(fr->value[0], truth, 3.0 * (fr->hi[0] - fr->lo[0]) / (2 * 1.96),
                   "3 sd of the interval");
        CHECK(fr->parts[0].pvalue > 0.001);
        CHECK_NEAR(fr->scene.restitution, fr->value[0], 1e-12, "the scene holds the fit");
        double s = 0.0;
        for (int c = 0; c < fr->parts[0].nclasses; c++) {
            s += fr->parts[0].p[c];
            CHECK(fr->parts[0].lo[c] <= fr->parts[0].p[c] && fr->parts[0].p[c] <= fr->parts[0].hi[c]);
        }
        CHECK_NEAR(s, 1.0, 1e-9, "the averaged probabilities sum to 1 (quantile bisection aside)");
        pd_note("box recovery: e = %.3f [%.3f, %.3f] (truth %.2f), X^2 %.2f p %.3f, %d evals, "
                "%ld drops\n", fr->value[0], fr->lo[0], fr->hi[0], truth, fr->parts[0].chi2,
                fr->parts[0].pvalue, fr->evaluations, fr->drops);
    }
    pd_fit_result_free(fr);

    if (pd_test_full()) {
        /* Coverage over repeats of posedrop's own drops, and narrowing. */
        enum { R = 20 };
        int covered = 0;
        double w300 = 0.0, w3000 = 0.0, w300_min = HUGE_VAL;
        for (int r = 0; r < R; r++) {
            CHECK(box_counts(&b, truth, 300, 2000 + (uint64_t)r, count));
            fr = NULL;
            pd_fit_part fp = {b.part, b.res, b.class_of, b.nclasses, count, NULL, 0};
            pd_fit_param prm = {"restitution", 0.05, 0.7, 0, 0};
            pd_fit_options o = fit_opts(500, 150, 0);
            o.seed = 3000 + (uint64_t)r;
            pd_diag diag;
            pd_diag_init(&diag);
            CHECK_STATUS(pd_fit_run(&fp, 1, &prm, 1, NULL, &o, &fr, &diag), PD_OK);
            if (fr) {
                covered += fr->lo[0] <= truth && truth <= fr->hi[0];
                w300 += fr->hi[0] - fr->lo[0];
                if (fr->hi[0] - fr->lo[0] < w300_min)
                    w300_min = fr->hi[0] - fr->lo[0];
            }
            pd_fit_result_free(fr);
        }
        double bound = R * 0.95 - 3.0 * sqrt(R * 0.95 * 0.05);
        CHECK(covered >= bound);
        CHECK(box_counts(&b, truth, 3000, 5000, count));
        fr = NULL;
        CHECK_STATUS(box_fit(&b, count, box_e, 5000, 40, 16, &fr), PD_OK);
        if (fr)
            w3000 = fr->hi[0] - fr->lo[0];
        pd_fit_result_free(fr);
        /* 10 times the data: narrower than every one of the 20 intervals
         * of 300 drops (were the widths alike, a 1 in 21 chance). Not
         * sqrt(10) narrower: the box barely feels its restitution, and at
         * 300 drops the intervals span most of the range, which caps them. */
        CHECK(w3000 < w300_min);
        pd_note("box coverage: %d of %d (bound %.1f); widths %.3f (narrowest %.3f) at 300 "
                "drops, %.3f at 3000\n", covered, R, bound, w300 / R, w300_min, w3000);
    }
    box_free(&b);
}

/* The contact time in multiples of each part's automatic duration: for one
 * part, the same fit as in seconds over the range scaled by that duration
 * (the same drops at every point: an invariance, to the round-off of the
 * log scale's ends); the fitted scene gives every part its own multiple of
 * its own duration. */
static void test_contact_multiple(const box_part *bp)
{
    box_part b = *bp;
    long count[8] = {240, 48, 12, 0, 0, 0, 0, 0};
    double a = pd_contact_time_auto_part(b.part);
    pd_fit_result *fx = NULL, *fs = NULL;
    const pd_fit_param in_auto = {"contact_time", 0.3, 3.0, 1, 1};
    const pd_fit_param in_s = {"contact_time", 0.3 * a, 3.0 * a, 1, 0};
    CHECK_STATUS(box_fit(&b, count, in_auto, 100, 8, 2, &fx), PD_OK);
    CHECK_STATUS(box_fit(&b, count, in_s, 100, 8, 2, &fs), PD_OK);
    if (fx && fs) {
        /* Round-off: the log of the ends, a few ulps each, compounded over
         * the simplex's steps. */
        CHECK_REL(fx->value[0] * a, fs->value[0], 1e-9, "the same fit, scaled by auto");
        CHECK_REL(fx->lo[0] * a, fs->lo[0], 1e-9, "the same fit, scaled by auto");
        CHECK_REL(fx->hi[0] * a, fs->hi[0], 1e-9, "the same fit, scaled by auto");
        CHECK_REL(fx->loglik, fs->loglik, 1e-12, "the same drops, the same counts");
        CHECK_INT(fx->evaluations, fs->evaluations);
        const pd_dist *d = &fx->scene.range[PD_PARAM_CONTACT_TIME];
        CHECK_INT(d->auto_multiple, 1);
        CHECK(d->lo == fx->value[0] && d->hi == fx->value[0]);
        /* A part twice the size gets twice its duration (similar parts:
         * auto goes as the size), from the same scene. */
        pd_vec3 pts[8];
        pd_diag diag;
        pd_diag_init(&diag);
        pd_part *big = part_of(convex_mesh(pts, pts_box(0.02, 0.04, 0.06, pts)), NULL, &diag);
        CHECK(big != NULL);
        if (big) {
            double v[PD_NPARAMS];
            pd_scene_draw(&fx->scene, pd_contact_time_auto_size(big), 1, 7, v, NULL);
            CHECK_REL(v[PD_PARAM_CONTACT_TIME], fx->value[0] * pd_contact_time_auto_part(big),
                      1e-12, "a product and a quotient of doubles");
            CHECK_REL(v[PD_PARAM_CONTACT_TIME], 2.0 * fx->value[0] * a, 1e-9,
                      "auto in proportion to the size for similar parts");
        }
        pd_part_free(big);
    }
    pd_fit_result_free(fx);
    pd_fit_result_free(fs);
    fx = NULL;
    /* Multiples are the contact time's only, within auto's 1e-3 to 1e3. */
    const pd_fit_param not_ct = {"mu", 0.1, 0.5, 0, 1}, two = {"contact_time", 0.3, 3.0, 1, 2};
    const pd_fit_param beyond = {"contact_time", 0.3, 2e3, 1, 1};
    CHECK_STATUS(box_fit(&b, count, not_ct, 100, 8, 2, &fx), PD_ERR_USAGE);
    CHECK_STATUS(box_fit(&b, count, two, 100, 8, 2, &fx), PD_ERR_USAGE);
    CHECK_STATUS(box_fit(&b, count, beyond, 100, 8, 2, &fx), PD_ERR_RANGE);
    CHECK(fx == NULL);
}

/* The initial mode as a discrete choice: each fitted, the best kept. */
static void test_initial_choice(const box_part *bp)
{
    box_part b = *bp;
    long count[8] = {240, 48, 12, 0, 0, 0, 0, 0};
    pd_fit_part fp = {b.part, b.res, b.class_of, b.nclasses, count, NULL, 0};
    pd_fit_param prm = {"restitution", 0.05, 0.7, 0, 0};
    pd_fit_options o = fit_opts(100, 5, 2);
    o.fit_initial = 1;
    pd_fit_result *fr = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(pd_fit_run(&fp, 1, &prm, 1, NULL, &o, &fr, &diag), PD_OK);
    if (fr) {
        double best = -HUGE_VAL;
        int arg = -1;
        for (int i = 0; i < 3; i++) {
            CHECK(isfinite(fr->loglik_initial[i]));
            if (fr->loglik_initial[i] > best) {
                best = fr->loglik_initial[i];
                arg = i;
            }
        }
        CHECK_INT((int)fr->initial, arg);
        CHECK_INT((int)fr->scene.initial, arg);
        /* The maximum is re-evaluated with the same drops: the same value
         * (the simulated frequencies recovered from the smoothed ones). */
        const pd_fit_part_result *q = &fr->parts[0];
        double ps[8], ka = q->nclasses * o.alpha;
        for (int c = 0; c < q->nclasses; c++)
            ps[c] = (q->p_best[c] * ((double)q->nsim + ka) - o.alpha) / (double)q->nsim;
        CHECK_NEAR(pd_fit_loglik_dm(q->nclasses, count, ps, (double)q->nsim, o.alpha), best,
                   1e-9 * fabs(best), "the same drops, round-off of sums");
        CHECK_INT(fr->initial_untested, 1);
    }
    pd_fit_result_free(fr);
    /* Two parts: each mode scored by the parts predicted from fits to the
     * other, the best scorer kept, and the untested flag down. */
    long other[8] = {200, 70, 30, 0, 0, 0, 0, 0};
    pd_fit_part two[2] = {fp, fp};
    two[1].count = other;
    fr = NULL;
    CHECK_STATUS(pd_fit_run(two, 2, &prm, 1, NULL, &o, &fr, &diag), PD_OK);
    if (fr) {
        int arg = 0;
        for (int i = 0; i < 3; i++) {
            CHECK(isfinite(fr->loglik_initial[i]) && fr->loglik_initial[i] < 0);
            arg = fr->loglik_initial[i] > fr->loglik_initial[arg] ? i : arg;
        }
        CHECK_INT((int)fr->initial, arg);
        CHECK_INT(fr->initial_untested, 0);
    }
    pd_fit_result_free(fr);
}

static void test_errors(const box_part *bp)
{
    box_part b = *bp;
    long count[8] = {10, 5, 1, 0, 0, 0, 0, 0};
    pd_fit_part fp = {b.part, b.res, b.class_of, b.nclasses, count, NULL, 0};
    pd_fit_result *fr = NULL;
    pd_fit_options fo;
    pd_fit_options_default(&fo);
    pd_diag diag;
    pd_diag_init(&diag);
    pd_fit_param bad_key = {"colour", 0, 1, 0, 0};
    CHECK_STATUS(pd_fit_run(&fp, 1, &bad_key, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    CHECK(strstr(diag.message, "colour") != NULL);
    pd_fit_param empty = {"mu", 0.5, 0.5, 0, 0};
    CHECK_STATUS(pd_fit_run(&fp, 1, &empty, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    pd_fit_param outside = {"restitution", 0.5, 1.5, 0, 0};
    CHECK_STATUS(pd_fit_run(&fp, 1, &outside, 1, NULL, &fo, &fr, &diag), PD_ERR_RANGE);
    pd_fit_param twice[] = {{"mu", 0.1, 0.5, 0, 0}, {"mu", 0.2, 0.6, 0, 0}};
    CHECK_STATUS(pd_fit_run(&fp, 1, twice, 2, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    pd_fit_param logzero = {"contact_time", 0.0, 1e-3, 1, 0};
    CHECK_STATUS(pd_fit_run(&fp, 1, &logzero, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    pd_fit_param ok = {"mu", 0.1, 0.5, 0, 0};
    CHECK_STATUS(pd_fit_run(&fp, 1, &ok, 0, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    pd_fit_part nocount = fp;
    nocount.count = NULL;
    CHECK_STATUS(pd_fit_run(&nocount, 1, &ok, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    long zero[8] = {0};
    pd_fit_part zeros = fp;
    zeros.count = zero;
    CHECK_STATUS(pd_fit_run(&zeros, 1, &ok, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    long negative[8] = {3, -1, 0};
    pd_fit_part neg = fp;
    neg.count = negative;
    CHECK_STATUS(pd_fit_run(&neg, 1, &ok, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    /* Counts whose sum overflows a long (signed overflow, then a fit that
     * returned OK) or passes what anyone measures. */
    long huge[8] = {LONG_MAX, LONG_MAX, 0};
    pd_fit_part over = fp;
    over.count = huge;
    CHECK_STATUS(pd_fit_run(&over, 1, &ok, 1, NULL, &fo, &fr, &diag), PD_ERR_RANGE);
    CHECK(strstr(diag.message, "add up to more than") != NULL);
    pd_fit_part wrongk = fp;
    wrongk.nclasses = b.nclasses + 1;
    CHECK_STATUS(pd_fit_run(&wrongk, 1, &ok, 1, NULL, &fo, &fr, &diag), PD_ERR_USAGE);
    CHECK_STATUS(pd_fit_run(&fp, 1, &ok, 1, NULL, NULL, &fr, &diag), PD_ERR_USAGE);
    CHECK(strstr(diag.message, "options") != NULL);
    CHECK(fr == NULL);
}

static void *cancel_soon(void *flag)
{
    struct timespec ts = {0, 50000000};
    nanosleep(&ts, NULL);
    atomic_store((pd_cancel_flag *)flag, 1);
    return NULL;
}

/* The cancel flag: set before the call, the fit returns at once; set from
 * another thread while it runs (a fit of 10^5 drops per evaluation, minutes
 * of work), it stops with PD_ERR_CANCELLED and no result. */
static void test_cancel(const box_part *bp)
{
    box_part b = *bp;
    long count[8] = {10, 5, 1, 0, 0, 0, 0, 0};
    pd_fit_part fp = {b.part, b.res, b.class_of, b.nclasses, count, NULL, 0};
    pd_fit_param mu = {"mu", 0.1, 0.5, 0, 0};
    pd_fit_options fo;
    pd_fit_options_default(&fo);
    CHECK(fo.cancel == NULL);
    pd_cancel_flag flag;
    atomic_init(&flag, 1);
    fo.cancel = &flag;
    fo.ndrops = 100000;
    pd_fit_result *fr = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(pd_fit_run(&fp, 1, &mu, 1, NULL, &fo, &fr, &diag), PD_ERR_CANCELLED);
    CHECK(fr == NULL && strstr(diag.message, "cancelled") != NULL);
    atomic_store(&flag, 0);
    pthread_t t;
    if (pthread_create(&t, NULL, cancel_soon, &flag) != 0) {
        CHECK(!"cannot start a thread");
        return;
    }
    CHECK_STATUS(pd_fit_run(&fp, 1, &mu, 1, NULL, &fo, &fr, &diag), PD_ERR_CANCELLED);
    pthread_join(t, NULL);
    CHECK(fr == NULL);
}

/* What the progress callback saw: the plan, the last report, the stages. */
typedef struct {
    pd_fit_progress plan, last;
    int calls, stages; /* bit per stage seen, in the order of names below */
} progress_seen;

static void progress_record(const pd_fit_progress *g, void *user)
{
    static const char *const names[] = {"design", "search", "final", "weighting", "prediction",
                                        "fresh"};
    progress_seen *s = user;
    if (s->calls++ == 0)
        s->plan = *g;
    s->last = *g;
    for (int i = 0; i < 6; i++)
        if (strcmp(g->stage, names[i]) == 0)
            s->stages |= 1 << i;
}

/* The plan before the first evaluation bounds what the fit spends
 * (evaluations and drops, the search's cheaper levels included), the last
 * report is the result's count, and every stage reports, a predicted
 * part's among them. */
static void test_progress(const box_part *bp)
{
    box_part b = *bp, other;
    CHECK(box_make_sized(&other, 0.01, 0.013, 0.035));
    long count[8] = {240, 48, 12, 0, 0, 0, 0, 0};
    pd_fit_part fp[2] = {{b.part, b.res, b.class_of, b.nclasses, count, NULL, 0},
                         {other.part, other.res, other.class_of, other.nclasses, NULL, NULL, 0}};
    pd_fit_param prm[2] = {{"restitution", 0.05, 0.7, 0, 0}, {"mu", 0.1, 0.8, 0, 0}};
    pd_fit_options o = fit_opts(60, 8, 3);
    o.threads = 1;
    progress_seen seen = {0};
    o.progress = progress_record;
    o.progress_user = &seen;
    pd_fit_result *fr = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    CHECK_STATUS(pd_fit_run(fp, 2, prm, 2, NULL, &o, &fr, &diag), PD_OK);
    if (fr) {
        CHECK(strcmp(seen.plan.stage, "start") == 0 && seen.plan.evaluation == 0);
        CHECK_INT(seen.last.evaluation, fr->evaluations);
        CHECK_INT(seen.last.drops, fr->drops);
        CHECK(fr->evaluations <= seen.plan.max_evaluations);
        CHECK(fr->drops <= seen.plan.max_drops);
        CHECK_INT(seen.stages, 63);
        pd_note("progress: %d evaluations of at most %d, %ld drops of at most %ld\n",
                fr->evaluations, seen.plan.max_evaluations, fr->drops, seen.plan.max_drops);
    }
    pd_fit_result_free(fr);
    box_free(&other);
}

/* The fits of the 1 x 2 x 3 cm box that need no recovery: one box for all. */
static void test_box_fits(void)
{
    box_part b;
    CHECK(box_make(&b));
    if (b.class_of) {
        test_initial_choice(&b);
        test_contact_multiple(&b);
        test_errors(&b);
        test_cancel(&b);
        test_progress(&b);
    }
    box_free(&b);
}

/* Whether the file at path has a line starting with key that holds what. */
static int stext_has(const char *path, const char *key, const char *what)
{
    char *text = slurp(path);
    const char *line = text ? strstr(text, key) : NULL;
    const char *end = line ? strchr(line + 1, '\n') : NULL;
    const char *hit = line ? strstr(line, what) : NULL;
    int ok = hit && (!end || hit < end);
    free(text);
    return ok;
}

/* posedrop fit as a user runs it: refused input (exit 2, nothing on
 * stdout, a message naming the problem), and a small fit whose scene file
 * --scene reads back and whose rows sum to one per part. */
static void test_command(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-fit-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        CHECK(!"cannot create a temporary directory");
        return;
    }
    char counts[128], scene[128], params[128], args[1024];
    snprintf(counts, sizeof counts, "%s/box.csv", tmpdir);
    snprintf(scene, sizeof scene, "%s/fitted.scene", tmpdir);
    snprintf(params, sizeof params, "%s/params.csv", tmpdir);
    write_file(counts, "pose,count\n1,240\n2,48\n3,12\n");
    const char *box = "--part parts/canonical/box_1x2x3.off";
    snprintf(args, sizeof args, "fit %s --measured %s", box, counts);
    expect_failure(args, 2, "nothing to fit");
    snprintf(args, sizeof args, "fit --fit mu %s --measured %s", box, counts);
    expect_failure(args, 2, "KEY=LO:HI");
    snprintf(args, sizeof args, "fit --fit mu=0.5:0.2 %s --measured %s", box, counts);
    expect_failure(args, 2, "LO < HI");
    snprintf(args, sizeof args, "fit --fit mu=0.1:x %s --measured %s", box, counts);
    expect_failure(args, 2, "two numbers");
    snprintf(args, sizeof args, "fit --fit contact_time=0.3x:3 %s --measured %s", box, counts);
    expect_failure(args, 2, "both ends");
    snprintf(args, sizeof args, "fit --fit mu=0.1x:0.5x %s --measured %s", box, counts);
    expect_failure(args, 2, "only contact_time");
    snprintf(args, sizeof args, "fit --fit colour=0:1 %s --measured %s", box, counts);
    expect_failure(args, 2, "colour");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s", box);
    expect_failure(args, 2, "--measured");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 --predict parts/canonical/box_1x2x3.off");
    expect_failure(args, 2, "no part to fit");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s/none.csv", box, tmpdir);
    expect_failure(args, 2, "none.csv");
    char many[128];
    snprintf(many, sizeof many, "%s/many.csv", tmpdir);
    write_file(many, "pose,count\n1,1\n9,2\n");
    /* A file in millimetres read as metres is warned about as the command
     * warns, before the fit (here refused at its counts). */
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 --part parts/hexnut.obj --measured %s", many);
    expect_failure(args, 2, "hexnut.obj: the part is 20.9 m across; if the file is in "
                            "millimetres, add --units mm");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s", box, many);
    expect_failure(args, 2, "pose class 9, but");
    /* Sets of poses: one pose in two rows is refused, and so is a set given
     * to a plain run, which has no likelihood to put it in. */
    write_file(many, "pose,count\n1|2,5\n2,3\n");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s", box, many);
    expect_failure(args, 2, "pose 2 given twice");
    write_file(many, "pose,count\n1|1,5\n");
    expect_failure(args, 2, "3|4");
    write_file(many, "pose,count\n1|2,5\n3,3\n");
    snprintf(args, sizeof args, "--measured %s --chart %s/c.svg parts/canonical/box_1x2x3.off",
             many, tmpdir);
    expect_failure(args, 2, "posedrop fit");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 -n 5 %s --measured %s", box, counts);
    expect_failure(args, 2, "number of drops");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s --out %s/no/dir/x", box,
             counts, tmpdir);
    expect_failure(args, 2, "no/dir");

    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s --out %s", box, counts,
             counts);
    expect_failure(args, 2, "box.csv");
    snprintf(args, sizeof args, "fit --fit mu=0.1:0.5 %s --measured %s --out %s --gof %s", box,
             counts, scene, scene);
    expect_failure(args, 2, "fitted.scene");
    /* A range of the base scene stays a range in the fitted one. */
    char base[128];
    snprintf(base, sizeof base, "%s/base.scene", tmpdir);
    write_file(base, "tumble = 0:1\n");
    snprintf(args, sizeof args, "fit --fit restitution=0.05:0.7,contact_time=0.3x:3x -n 100 "
             "--max-evals 5 --points 2 "
             "%s --measured %s --predict parts/canonical/box_1x1x2.off --out %s --params %s "
             "--scene %s", box, counts, scene, params, base);
    char *out = NULL, *err = NULL;
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(out &&
          strncmp(out, "part,role,pose,count,p_measured,p_best,p,ci_lo,ci_hi,set\n", 57) == 0);
    double sum[2] = {0, 0};
    int rows = 0;
    for (const char *line = out ? strchr(out, '\n') : NULL; line && line[1]; line = strchr(line + 1, '\n')) {
        char role[16];
        int pose;
        double p_best, p, lo, hi;
        const char *c = strchr(line + 1, ',');
        if (!c || sscanf(c + 1, "%15[a-z],%d,", role, &pose) != 2)
            break;
        const char *f = c + 1;
        for (int i = 0; i < 4 && f; i++) /* role, pose, count, p_measured */
            f = strchr(f, ',') ? strchr(f, ',') + 1 : NULL;
        if (!f || sscanf(f, "%lf,%lf,%lf,%lf", &p_best, &p, &lo, &hi) != 4)
            break;
        sum[strcmp(role, "fitted") != 0] += p;
        CHECK(lo <= p && p <= hi);
        rows++;
    }
    CHECK_INT(rows, 3 + 2);
    CHECK_NEAR(sum[0], 1.0, 1e-6, "averaged probabilities sum to 1; quantile bisection aside");
    CHECK_NEAR(sum[1], 1.0, 1e-6, "averaged probabilities sum to 1; quantile bisection aside");
    CHECK(err && strstr(err, "restitution = ") != NULL);
    free(out);
    free(err);
    /* Sets of poses: posedrop's poses of the box counted in mirror pairs,
     * each pair one row, and its members named by the set column. */
    char pairs[128];
    snprintf(pairs, sizeof pairs, "%s/pairs.csv", tmpdir);
    write_file(pairs, "pose,count\n1|2,200\n3|4,70\n5|6,30\n");
    snprintf(args, sizeof args, "fit --no-group --fit restitution=0.05:0.7 -n 100 --max-evals 5 "
             "--points 2 %s --measured %s", box, pairs);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(out && strstr(out, ",fitted,1,,,") && strstr(out, ",1|2\n") &&
          strstr(out, ",5|6\n"));
    free(out);
    free(err);
    /* The scene file is one --scene reads. */
    snprintf(args, sizeof args, "--scene %s -n 10 parts/canonical/box_1x2x3.off", scene);
    CHECK_INT(run(args, &out, &err), 0);
    free(out);
    free(err);
    char *stext = slurp(scene);
    CHECK(stext && strstr(stext, "\ntumble = 0:1\n") != NULL);
    /* Shortest round-trip numbers: the paper's gravity as typed. */
    CHECK(stext && strstr(stext, "\ngravity = 9.81\n") != NULL);
    CHECK(stext && strstr(stext, "\nrestitution = ") != NULL);
    free(stext);
    char *ptext = slurp(params);
    CHECK(ptext && strncmp(ptext, "parameter,value,lo,hi,mean,range_lo,range_hi,unit\n"
                                  "restitution,", 62) == 0);
    /* The contact time's values are multiples (unit auto), its range the
     * one given, and the scene holds the multiple for every part. */
    CHECK(ptext && strstr(ptext, ",0.3,3,auto\n") != NULL);
    CHECK(stext_has(scene, "\ncontact_time = ", "x\n"));
    free(ptext);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    CHECK(system(cmd) == 0);
}

/* A box of edges ax, ay, az, its poses and classes. */
static int box_make_sized(box_part *b, double ax, double ay, double az)
{
    pd_vec3 pts[8];
    int n = pts_box(ax, ay, az, pts);
    pd_diag diag;
    pd_diag_init(&diag);
    b->part = part_of(convex_mesh(pts, n), NULL, &diag);
    b->res = NULL;
    b->class_of = NULL;
    if (!b->part || pd_static_estimate(b->part, NULL, &b->res, &diag) != PD_OK)
        return 0;
    b->class_of = malloc(sizeof(int) * (size_t)b->res->nposes);
    return b->class_of &&
           pd_pose_classes(b->part, b->res, b->class_of, &b->nclasses, &diag) == PD_OK;
}

/* Class counts (count, or NULL) and probabilities (p, or NULL) of n drops
 * of b in scene sc from seed: p is the drops' frequencies, or with a
 * stationary start the estimated chain's long run. */
static int scene_classes(const box_part *b, const pd_scene *sc, long n, uint64_t seed,
                         long *count, double *p)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = n;
    o.seed = seed;
    o.threads = 1;
    pd_sim_result *r = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    if (pd_sim_run(b->part, b->res, sc, &o, &r, &diag) != PD_OK)
        return 0;
    for (int c = 0; c < b->nclasses; c++) {
        if (count)
            count[c] = 0;
        if (p)
            p[c] = 0.0;
    }
    for (int j = 0; j < r->nposes; j++) {
        if (count)
            count[b->class_of[j]] += r->count[j];
        if (p)
            p[b->class_of[j]] += r->p[j];
    }
    pd_sim_result_free(r);
    return 1;
}

/* n measured drops' class counts, drawn from p (k classes). */
static void draw_counts(test_rng *rng, int k, const double *p, long n, long *count)
{
    for (int c = 0; c < k; c++)
        count[c] = 0;
    for (long i = 0; i < n; i++) {
        double u = rng_uniform(rng), cum = 0.0;
        int c = 0;
        while (c < k - 1 && u >= (cum += p[c]))
            c++;
        count[c]++;
    }
}

/* What one case of the held-out coverage measured. */
typedef struct {
    int covered, covered_fit; /* the held-out main class: with the discrepancy, without */
    int all_cov, all_n;       /* every class of the held-out part, with it */
    double width, width_fit;  /* the main class's mean interval width, with it and without */
    double shift;             /* largest |truth - the fit's model at the truth's values| */
    double tau;               /* mean sqrt(discrepancy) */
} coverage;

/* The intervals' coverage where it matters to a user: fitted to two parts,
 * predicting a third. Of three boxes (1 x 2 x 3, 1 x 1.5 x 2.5 and 1 x 1.3 x
 * 3.5 cm), the two other than held are fitted for their restitution (0.05 to
 * 0.7) with posedrop's default scene (uniform start, friction 0.3), and held
 * is predicted; its classes' 95% intervals are checked against its
 * probabilities in the scene truth. Every box's truth comes from 20,000
 * drops (standard error below 0.0035, small beside the intervals), and each
 * of DATASETS data sets draws 150 measured drops per fitted box from it
 * (independent multinomials: the data sets are independent, as the
 * binomial bound below assumes); every fit runs on seeds of its own, with
 * 400 drops per part (100 in the search and at the weighting's points, as
 * scripts/paper.sh -L's), 12 simplex evaluations and 8 points a round.
 * The bound: at a true coverage of 95%, at least 90 of 100 intervals cover
 * with probability 0.988 (binomial); the test asks 90 of the main class's,
 * and 90% of every class's (the classes of one data set are not
 * independent, so that bound is looser). */
static void coverage_case(const char *what, const pd_scene *truth, int held, coverage *out)
{
    enum { DATASETS = 100, MEASURED = 150, TRUTH_DROPS = 20000, K = 8 };
    static const double edge[3][3] = {{0.01, 0.02, 0.03}, {0.01, 0.015, 0.025},
                                      {0.01, 0.013, 0.035}};
    box_part box[3];
    int ok = 1;
    for (int i = 0; i < 3; i++)
        ok &= box_make_sized(&box[i], edge[i][0], edge[i][1], edge[i][2]) &&
              box[i].nclasses <= K;
    CHECK(ok);
    memset(out, 0, sizeof *out);
    double p_true[3][K], p_model[K];
    pd_scene model;
    pd_scene_default(&model);
    model.restitution = truth->restitution;
    for (int i = 0; ok && i < 3; i++)
        ok = scene_classes(&box[i], truth, TRUTH_DROPS, 777 + (uint64_t)i, NULL, p_true[i]);
    ok = ok && scene_classes(&box[held], &model, TRUTH_DROPS, 888, NULL, p_model);
    CHECK(ok);
    const box_part *h = &box[held];
    for (int c = 0; ok && c < h->nclasses; c++)
        out->shift = fmax(out->shift, fabs(p_true[held][c] - p_model[c]));
    test_rng rng = {4000 + (uint64_t)held};
    long counts[3][K];
    for (int r = 0; ok && r < DATASETS; r++) {
        pd_fit_part fp[3];
        for (int i = 0; i < 3; i++) {
            if (i != held)
                draw_counts(&rng, box[i].nclasses, p_true[i], MEASURED, counts[i]);
            pd_fit_part one = {box[i].part, box[i].res, box[i].class_of, box[i].nclasses,
                               i == held ? NULL : counts[i], NULL, 0};
            fp[i] = one;
        }
        pd_fit_options o = fit_opts(400, 12, 8);
        o.threads = 1;
        o.seed = 30000 + (uint64_t)r;
        pd_fit_result *fr = NULL;
        pd_diag diag;
        pd_diag_init(&diag);
        CHECK_STATUS(pd_fit_run(fp, 3, &box_e, 1, NULL, &o, &fr, &diag), PD_OK);
        if (!fr)
            continue;
        const pd_fit_part_result *q = &fr->parts[held];
        const double *pt = p_true[held];
        out->covered += q->lo[0] <= pt[0] && pt[0] <= q->hi[0];
        out->covered_fit += q->lo_fit[0] <= pt[0] && pt[0] <= q->hi_fit[0];
        out->width += (q->hi[0] - q->lo[0]) / DATASETS;
        out->width_fit += (q->hi_fit[0] - q->lo_fit[0]) / DATASETS;
        out->tau += sqrt(fr->discrepancy) / DATASETS;
        for (int c = 0; c < q->nclasses; c++) {
            out->all_cov += q->lo[c] <= pt[c] && pt[c] <= q->hi[c];
            out->all_n++;
            /* The discrepancy only widens. */
            CHECK(q->lo[c] <= q->lo_fit[c] + 1e-9 && q->hi_fit[c] <= q->hi[c] + 1e-9);
        }
        /* The best value always inside its interval. */
        CHECK(fr->lo[0] <= fr->value[0] && fr->value[0] <= fr->hi[0]);
        pd_fit_result_free(fr);
    }
    pd_note("coverage, %s: main class %d of %d (truth %.4f, %.4f in the fit's model; largest "
            "class shift %.3f; mean width %.4f, tau %.3f), without the discrepancy %d (width "
            "%.4f); every class %d of %d\n", what, out->covered, DATASETS, p_true[held][0],
            p_model[0], out->shift, out->width, out->tau, out->covered_fit, out->width_fit,
            out->all_cov, out->all_n);
    for (int i = 0; i < 3; i++)
        box_free(&box[i]);
}

static void test_coverage_heldout(void)
{
    if (!pd_test_full())
        return;
    coverage cv;
    pd_scene truth;
    pd_scene_default(&truth);
    truth.restitution = 0.35;
    coverage_case("model right", &truth, 2, &cv);
    CHECK(cv.covered >= 90);
    CHECK(cv.all_cov >= 0.9 * cv.all_n);
    /* The model wrong: the counts come from a feeder's belt, each part
     * dropped from the poses it rested in (the stationary start), while the
     * fit drops from uniform orientations. The 1 x 1.3 x 3.5 cm box's long
     * run rests on one class alone, so the 1 x 1.5 x 2.5 cm box is
     * predicted. A case with power: its truth lies more than 0.08 (half an
     * interval of the model right) from the model's in some class. */
    truth.initial = PD_INITIAL_STATIONARY;
    coverage_case("model wrong (a stationary start, the fit's uniform)", &truth, 1, &cv);
    CHECK(cv.shift > 0.08);
    CHECK(cv.covered >= 90);
    CHECK(cv.all_cov >= 0.9 * cv.all_n);
}

void suite_fit(void)
{
    test_likelihood_hand();
    test_beta_mixture();
    test_search_closed_form();
    test_least_squares();
    test_dispersion();
    test_coverage_crn();
    test_recovery();
    test_box_fits();
    test_command();
    test_coverage_heldout();
}
