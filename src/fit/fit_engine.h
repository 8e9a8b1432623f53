/* fit_engine.h (private): maximum simulated likelihood and likelihood
 * weighting over a box of parameters, for any model that turns a parameter
 * vector into class probabilities per part (fit.c's is posedrop's drops; the
 * tests give closed forms). docs/calibration.md describes the method. */
#ifndef PD_FIT_ENGINE_H
#define PD_FIT_ENGINE_H

#include "posedrop/diag.h"
#include "posedrop/status.h"

/* How much simulation an evaluation gets (docs/calibration.md, "The
 * optimiser"): the search's design and simplex compare many points on few
 * drops, all of one seed (common random numbers); the two best points of the
 * search are then compared, and everything after (the intervals, the
 * predictions, the quality at the best point) computed, on drops of another
 * seed, so that the search's choice among the noise of its own drops does
 * not carry into what the fit reports. A simulated model sizes its drops by
 * the level; a closed form may ignore it. */
typedef enum fit_level {
    FIT_LEVEL_SEARCH = 0, /* a quarter of the drops, the search's seed */
    FIT_LEVEL_FULL,       /* all the drops, another seed */
    FIT_LEVEL_WEIGH,      /* a quarter of the drops, FIT_LEVEL_FULL's seed: the
                             weighting's points, whose likelihood (the Dirichlet-
                             multinomial) counts their larger simulation error */
    FIT_LEVEL_FRESH,      /* all the drops, a seed no other level uses (fit.c's check) */
    FIT_LEVEL_REPEAT      /* FIT_LEVEL_REPEAT + r, r in 0..FIT_REPEATS): FIT_LEVEL_WEIGH's
                             drops of the r-th seed of their own, to measure the
                             simulation's noise in the weighting's likelihood */
} fit_level;

/* The weighting's likelihood is evaluated this many times at the maximum,
 * each on drops of its own, for the variance of its simulation noise (the
 * centre points of a response-surface design, whose spread is the pure
 * error: Box and Draper 1987, Empirical Model-Building and Response
 * Surfaces, ch. 6). */
#define FIT_REPEATS 6

/* The predicted parts are simulated at up to this many times the
 * weighting's points per round, drawn by weight (fit_weigh). */
#define FIT_PREDICT_ROUNDS 4

/* Fills p[i][0..k[i]) (summing to 1) and nsim[i] (the simulated drops behind
 * them) for every part i with counts when all is 0, for every part when all
 * is 1, and for the parts without counts alone when all is 2 (a model may
 * fill more). theta is in the problem's scale (lo..hi). */
typedef pd_status (*fit_model_fn)(void *user, const double *theta, int all, fit_level level,
                                  double *const *p, double *nsim, pd_diag *diag);

typedef struct fit_problem {
    int d;                    /* parameters, 1..PD_FIT_MAX_PARAMS */
    const double *lo, *hi;    /* the box, lo < hi */
    int nparts;
    const int *k;             /* classes per part */
    const long *const *count; /* per part, one per cell; NULL: predicted only */
    const int *const *cell_of; /* per part: each class's cell of counts, or NULL (or
                                  cell_of NULL): every class its own cell */
    const int *ncells;        /* per part, with cell_of; NULL: k */
    double alpha;             /* the smoothing pseudo-count */
    fit_model_fn model;
    void *user;
    /* Called after every evaluation, when not NULL: the stage ("design",
     * "search", "weighting", "prediction"), the weighting's round (1..) or 0,
     * and the evaluation's log-likelihood (the parts with counts; 0 for a
     * prediction). */
    void (*note)(void *note_user, const char *stage, int round, double loglik);
    void *note_user;
} fit_problem;

typedef struct fit_settings {
    int max_evals; /* per Nelder-Mead search */
    int npoints;   /* weighted points per round */
} fit_settings;

/* The number of the search's best points compared at FIT_LEVEL_FULL. */
#define FIT_FINALISTS 2

/* The search: a quasi-random design over the box, then Nelder-Mead from its
 * best point (both at FIT_LEVEL_SEARCH), then the FIT_FINALISTS best points
 * the simplex saw evaluated at FIT_LEVEL_FULL. theta (d) receives the
 * best of those, *loglik its log-likelihood at FIT_LEVEL_FULL (the parts with
 * counts), *evals is increased by the evaluations spent. */
pd_status fit_search(const fit_problem *pb, const fit_settings *s, double *theta, double *loglik,
                     int *evals, pd_diag *diag);

/* What the weighting gives; the caller allocates every array. */
typedef struct fit_weighed {
    double *lo, *hi, *mean;   /* d: 95% interval and weighted mean */
    double *const *p_best;    /* per part, k[i]: smoothed probabilities at theta */
    double *nsim_best;        /* per part */
    double *const *p;         /* per part, k[i]: averaged */
    double *const *plo, *const *phi; /* per part, k[i]: 95% interval */
    double dispersion;        /* X^2 of the 2 x K tables of counts and drops at theta
                                 over what the noise explains (their degrees of freedom,
                                 less d in proportion), at least 1: the log-likelihood
                                 the weights use is divided by it */
    double ess;
    int npoints;
    double discrepancy;       /* tau^2, in [0, 0.9]: the fitted parts' X^2 beyond the noise
                                 read as a scatter of each part's true probabilities
                                 about the model's of variance tau^2 p (1 - p); the
                                 predicted parts' intervals carry it */
    double *const *plo_fit, *const *phi_fit; /* per part, k[i], or NULL: the 95%
                                 interval without the discrepancy */
    double noise_sd;          /* the weighting's log-likelihood's simulation noise at the
                                 maximum (standard deviation over FIT_REPEATS seeds) */
    double misfit_sd;         /* its points' scatter about the fitted quadratic beyond
                                 that noise (-1 when the quadratic was not fitted) */
} fit_weighed;

/* At FIT_LEVEL_FULL, evaluates theta (the search's maximum) with every part (and its
 * dispersion from there), then theta FIT_REPEATS times on the weighting's
 * drops of other seeds (the simulation's noise in its likelihood), then
 * rounds of s->npoints quasi-random points with the fitted parts: the whole
 * box, then boxes about the weighted mean shrunk to the weighted spread (at
 * least 3 rounds, at most 6, stopping once the effective sample size
 * reaches s->npoints), all weighed by their Dirichlet-multinomial
 * likelihood, smoothed against that noise by a quadratic, over the density
 * they were drawn from (the balance heuristic). The parts without counts are then simulated at
 * s->npoints of those points drawn by their weights (systematic
 * resampling), and averaged over them. The interval of every parameter
 * holds theta. */
pd_status fit_weigh(const fit_problem *pb, const fit_settings *s, const double *theta,
                    fit_weighed *out, int *evals, pd_diag *diag);

/* The most evaluations fit_weigh spends: the maximum, MAX_ROUNDS rounds and
 * the predicted parts' points. */
int fit_weigh_max_evals(const fit_settings *s);

/* The Halton sequence's coordinate j (0..6) of point i >= 1, in (0, 1). */
double fit_halton(long i, int j);

/* Pearson's X^2 of counts (k) against n p. */
double fit_chi2(int k, const long *count, const double *p);

/* With counts of cells of classes: class i of k in cell cell_of[i] (cell_of
 * NULL: every class its own cell, ncells = k); count has ncells entries.
 * The Dirichlet-multinomial log-likelihood, Pearson's X^2, and the
 * probability of cell j. */
double fit_loglik_cells(int k, const int *cell_of, int ncells, const long *count,
                        const double *p_sim, double nsim, double alpha);
double fit_chi2_cells(int k, const int *cell_of, int ncells, const long *count, const double *p);
double fit_cell_p(int k, const int *cell_of, int j, const double *p);

/* Pearson's X^2 of the 2 x K table of the counts (ncells cells) and nsim
 * simulated drops of frequencies p (per class), the test that both rows come
 * from one distribution, which counts the simulation's error as well as the
 * data's; the cells neither row reached are left out, and *df receives the
 * cells kept less one (0 when there are no counts or drops). */
double fit_chi2_two_sample(int k, const int *cell_of, int ncells, const long *count,
                           const double *p, double nsim, int *df);

/* The q-quantile of a mixture of Beta(a_j, b_j) with weights w_j (n terms,
 * summing to 1), by bisection to 1e-9. */
double fit_beta_mixture_quantile(int n, const double *w, const double *a, const double *b,
                                 double q);

#endif
