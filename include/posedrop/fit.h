/* posedrop/fit.h: calibrating the scene to measured drops.
 *
 * Given parts with measured counts per pose (or per pose class), pd_fit_run
 * finds the scene values, shared by all the parts (one feeder), that
 * maximise the multinomial likelihood of all the counts together, the
 * model's pose probabilities coming from simulated drops. Every evaluation
 * of the search runs the same drops (the same seed: common random numbers),
 * so that the simulated likelihood moves with the parameters and not with
 * the noise of fresh draws; its best points are compared, and everything
 * after computed, on drops of another seed. The search is GSL's Nelder-Mead simplex on the parameters
 * mapped onto the real line; the intervals and the averaged predictions
 * weigh points around the optimum by their likelihood (docs/calibration.md
 * gives the method and its sources). */
#ifndef POSEDROP_FIT_H
#define POSEDROP_FIT_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/part.h"
#include "posedrop/sim.h"
#include "posedrop/static.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* At most this many parameters are fitted at once (the quasi-random points
 * of the weighting use one prime per parameter). */
#define PD_FIT_MAX_PARAMS 7

/* One parameter to fit: a numeric key of pd_scene_set (height, belt_speed,
 * mu, restitution, vibration in degrees, gravity, contact_time in s, tumble
 * in rad/s), set to a plain value at every evaluation, and
 * the range searched, in the key's text units, lo < hi within the key's own
 * limits. log 1 searches and weighs log(value) (lo > 0): for a quantity
 * known to within a factor, such as the contact time. multiple 1
 * (contact_time only): lo, hi and the fitted values are multiples of each
 * part's own automatic contact time (pd_contact_time_auto_part), 1e-3 to
 * 1e3, one multiple shared by the parts ("0.3x:3x" of pd_scene_set), so
 * that parts of one material but different sizes share the value. */
typedef struct pd_fit_param {
    const char *key;
    double lo, hi;
    int log;
    int multiple;
} pd_fit_param;

/* The most measured drops a part's counts may add up to: far more than any
 * feeder is observed for, far below where a sum of counts overflows. */
#define PD_FIT_MAX_COUNT 1000000000000000L

/* One part. count NULL: the part is not fitted, only predicted at the
 * fitted values (and averaged over the values the data allow). Its counts
 * add up to at most PD_FIT_MAX_COUNT (PD_ERR_RANGE otherwise). */
typedef struct pd_fit_part {
    const pd_part *part;
    const pd_static_result *poses; /* its stable poses (pd_static_estimate) */
    const int *class_of;  /* poses->nposes classes in [0, nclasses) (pd_pose_classes),
                             or NULL: every pose its own class */
    int nclasses;         /* with class_of NULL: poses->nposes */
    const long *count;    /* nclasses measured counts (>= 0, not all 0), or NULL; with
                             cell_of, ncells counts */
    /* Counts of sets of classes, for a label that stands for several poses
     * (a die's face read as either of two facets, counts folded by mirror
     * pairs): class c was counted in cell cell_of[c] (0 .. ncells - 1, each
     * cell holding at least one class), and its likelihood is that of the
     * cell, the sum of its classes' probabilities. NULL: every class its own
     * cell (ncells is then ignored). */
    const int *cell_of;
    int ncells;
} pd_fit_part;

/* Where a fit stands, after each evaluation (and once before the first, with
 * evaluation 0): for a progress line, never needed for the result. */
typedef struct pd_fit_progress {
    const char *stage;     /* "design", "search", "final" (the search's best points on
                              the full drops), "repeat" (the best point on other
                              drops, for the simulation's noise), "weighting",
                              "prediction", "fresh", and "start" before the first
                              evaluation */
    const char *initial;   /* the initial mode being searched */
    int held_out;          /* choosing the initial mode: the part left out (1..), else 0 */
    int round;             /* the weighting's round (1..6), else 0 */
    int evaluation;        /* evaluations spent */
    int max_evaluations;   /* the most the fit can spend (planned at the start) */
    long drops;            /* drops simulated */
    long max_drops;        /* the most the fit can simulate */
    double best_loglik;    /* the best log-likelihood of the current search or
                              weighting so far (-HUGE_VAL before one; the
                              Dirichlet-multinomial's, not the weights' tempered one) */
} pd_fit_progress;

typedef void (*pd_fit_progress_fn)(const pd_fit_progress *progress, void *user);

typedef struct pd_fit_options {
    long ndrops;        /* simulated drops per part and evaluation, >= 10; 1000
                           (raised to what --initial stationary needs). The
                           search and the weighting's points run a quarter of
                           them (docs/calibration.md, "The optimiser") */
    uint64_t seed;      /* 1: the search's drops use it (common random numbers), the
                           later stages seeds derived from it */
    int threads;        /* 0: all cores */
    pd_engine_kind engine; /* PD_ENGINE_IMPULSE */
    int fit_initial;    /* 1: the initial mode is fitted too, as a discrete choice:
                           uniform, bootstrap and stationary are each fitted and the
                           one of highest maximised likelihood kept; 0 */
    int max_evals;      /* Nelder-Mead evaluations per search, >= 1; 150. The simplex
                           stops once it has spent them, finishing its step (up to
                           max_evals + d + 1); each search's design (4 d + 1) and
                           final 2, the weighting, the predicted parts and the
                           fresh drops come on top (pd_fit_progress's
                           max_evaluations adds them up) */
    int npoints;        /* likelihood-weighted points per round (3 to 6 rounds),
                           >= 1; 0: 8 (d + 1) for d parameters */
    double alpha;       /* pseudo-count added to every class's simulated count
                           (Dirichlet smoothing), > 0; 0.5 (Jeffreys) */
    pd_cancel_flag *cancel; /* may be NULL. Set non-zero (atomic_store, from any
                           thread or a signal handler, as pd_sim_options' cancel)
                           to stop the fit: the drops under way stop, and
                           pd_fit_run returns PD_ERR_CANCELLED with no result.
                           Only read, never reset; NULL by default */
    pd_fit_progress_fn progress; /* NULL: none */
    void *progress_user;
} pd_fit_options;

PD_API void pd_fit_options_default(pd_fit_options *options);

/* The counts against drops simulated afresh (a seed no evaluation used), so
 * that the fit's own drops, which chose the values, do not flatter it: Pearson's X^2 of the 2 x K table of measured and simulated
 * counts (the test that both come from one distribution, which counts the
 * simulation's error), its degrees of freedom, p, and the total variation
 * distance between the measured and the simulated frequencies. */
typedef struct pd_fit_quality {
    double chi2;
    int df;             /* classes seen in either row, minus 1; for all parts,
                           their sum minus the fitted parameters (<= 0: the data
                           cannot test the fit) */
    double pvalue;      /* 1 when df <= 0 */
    double tv;          /* half the sum of |measured - simulated| frequencies */
} pd_fit_quality;

/* What the fit says about one part; arrays of nclasses. */
typedef struct pd_fit_part_result {
    int nclasses;
    long n;             /* measured drops (0 for a predicted part) */
    long nsim;          /* simulated drops per evaluation */
    double *p_best;     /* the smoothed simulated probabilities at the best fit */
    double *p, *lo, *hi; /* averaged over the likelihood-weighted points, and the
                           95% interval of the probability, which carries the
                           parameters' spread and the simulation's own error,
                           and for a predicted part the model's discrepancy
                           (pd_fit_result's) */
    double *lo_fit, *hi_fit; /* the 95% interval without the discrepancy: what
                           the parameters and the drops leave open if the model
                           were right (lo, hi for a fitted part) */
    double loglik;      /* sum_k count_k log p_best_k (0 for a predicted part) */
    double chi2;        /* Pearson's X^2 of the 2 x K table of the counts and the
                           best point's drops (the cells neither reached left out) */
    int df;             /* its cells less one (a predicted part: its cells of
                           counts - 1) */
    double pvalue;      /* P(chi2_df > chi2) */
    double tv;          /* total variation between the counts and p_best: in-sample */
    pd_fit_quality fresh_best, fresh_mean; /* against fresh drops at the best
                           values and at the weighted means (fitted parts only) */
} pd_fit_part_result;

typedef struct pd_fit_result {
    int nparams;
    double *value;      /* the maximum found (Nelder-Mead), in the key's text units */
    double *lo, *hi;    /* 95% interval: quantiles of the likelihood-weighted points */
    double *mean;       /* the weighted mean */
    pd_scene scene;     /* the base scene with the fitted values (and initial mode) */
    pd_initial initial; /* the initial mode used (the one chosen with fit_initial) */
    double loglik_initial[3]; /* per initial mode tried (indexed by pd_initial;
                                 -HUGE_VAL if not tried): with two or more fitted
                                 parts, the log-likelihood of each part's counts
                                 predicted by a fit to the others, summed over the
                                 parts (the mode kept is the best predictor); with
                                 one, the maximised log-likelihood */
    int initial_untested; /* 1: the initial mode was chosen on one part's own
                             counts, which cannot test it */
    double loglik;      /* at the maximum, all fitted parts: sum_k count_k log p_k */
    double chi2;        /* the parts' X^2 summed: in-sample, a diagnostic (these
                           drops chose the best values between the search's two best) */
    int df;             /* sum of (nclasses - 1) over the fitted parts, minus nparams;
                           <= 0: the data cannot test the fit */
    double pvalue;      /* 1 when df <= 0 */
    pd_fit_quality fresh_best, fresh_mean; /* all fitted parts, against fresh drops */
    double dispersion;  /* >= 1: the parts' X^2 at the best fit (the 2 x K tables of
                           counts and simulated drops) over what the data's
                           and the simulation's noise explain; the weights' log-
                           likelihood is divided by it, widening the intervals by
                           its square root when no value reproduces the counts */
    double discrepancy; /* tau^2 in [0, 0.9]: the fitted parts' X^2 beyond their
                           noise read as each part's true probabilities scattering
                           about the model's with variance tau^2 p (1 - p) (0 when
                           the model fits within the noise); a predicted part's
                           interval carries that scatter */
    int npoints;        /* weighted points */
    double ess;         /* their effective sample size (sum w)^2 / sum w^2 */
    int evaluations;    /* likelihood evaluations, all searches and points */
    long drops;         /* drops simulated in all */
    int nparts;
    pd_fit_part_result *parts; /* in the order given */
    long failed;        /* of the drops simulated, those that failed (a solver
                           could not go on): in no count, as in pd_sim_run */
    double weigh_noise_sd;  /* the weighting's log-likelihood at the maximum: its
                               standard deviation over sets of drops (the simulation's
                               noise the weights are smoothed against) */
    double weigh_misfit_sd; /* the weighting's points' scatter about their fitted
                               quadratic beyond that noise; -1: no quadratic fitted */
} pd_fit_result;

/* Fits params (nparams in 1..PD_FIT_MAX_PARAMS, distinct keys) to the parts
 * with counts (at least one) and predicts those without. base holds the
 * values of everything not fitted (NULL: pd_scene_default); options are
 * required (pd_fit_options_default fills them), since they set what the fit
 * costs. Every part's drops run from the same seed at every evaluation. A
 * class the measurements saw and the drops never reached gets the smoothed
 * probability alpha / (nsim + K alpha) instead of 0, so that no value makes
 * the likelihood minus infinity. PD_ERR_USAGE (a bad argument: the message
 * names it), PD_ERR_RANGE (a range outside its key's limits), PD_ERR_NOMEM,
 * PD_ERR_CANCELLED (options->cancel set), PD_ERR_NO_CONVERGENCE when every
 * drop of a part at one evaluation failed, and what pd_sim_run returns. On success *result is the caller's
 * (pd_fit_result_free). */
PD_API pd_status pd_fit_run(const pd_fit_part *parts, int nparts, const pd_fit_param *params,
                            int nparams, const pd_scene *base, const pd_fit_options *options,
                            pd_fit_result **result, pd_diag *diag);

PD_API void pd_fit_result_free(pd_fit_result *result);

/* The smoothed probabilities of k classes from simulated ones: p_sim (k,
 * summing to 1) from nsim drops, each class given alpha more drops, the
 * posterior mean under a Dirichlet(alpha) prior: (nsim p_k + alpha) /
 * (nsim + k alpha), into out (k). Does nothing when p_sim or out is NULL. */
PD_API void pd_fit_smooth(int k, const double *p_sim, double nsim, double alpha, double *out);

/* The log-likelihood of counts (k) under the smoothed probabilities of
 * p_sim: sum_k count_k log(pd_fit_smooth's p_k), without the multinomial
 * coefficient (it does not depend on the scene). Finite for alpha > 0; 0
 * (no counts) when count or p_sim is NULL. */
PD_API double pd_fit_loglik(int k, const long *count, const double *p_sim, double nsim,
                            double alpha);

/* The Dirichlet-multinomial log-likelihood of counts (k) given nsim simulated
 * drops whose class frequencies are p_sim: the probability of the counts
 * averaged over what the simulated drops leave open about the classes'
 * probabilities (their posterior Dirichlet(nsim p_sim + alpha)),
 * sum_k [lnGamma(s_k + alpha + c_k) - lnGamma(s_k + alpha)] - [lnGamma(nsim +
 * k alpha + n) - lnGamma(nsim + k alpha)] with s_k = nsim p_sim_k, without the
 * multinomial coefficient. It tends to pd_fit_loglik as nsim grows; this is
 * what the fit maximises and weighs (docs/calibration.md). 0 when count or
 * p_sim is NULL. */
PD_API double pd_fit_loglik_dm(int k, const long *count, const double *p_sim, double nsim,
                               double alpha);

#ifdef __cplusplus
}
#endif
#endif
