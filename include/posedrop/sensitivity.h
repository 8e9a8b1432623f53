/* posedrop/sensitivity.h: what each ranged scene parameter moves.
 *
 * A run whose scene has ranges (pd_scene.range) gives every pose a
 * probability over those ranges. For each pose and each ranged parameter,
 * this says how much of the pose's variation the parameter explains: its
 * first-order variance-based (Sobol') index
 *     S_i = Var(E[Y | X_i]) / Var(Y),
 * Y the drop's pose indicator (1 if the drop ended in the pose), X_i the
 * parameter's drawn value; the pose's probability in the lower and
 * upper thirds of the range and their difference, the effect in
 * probability points, with a bootstrap interval; and where one parameter's
 * effect changes across another's thirds (an interaction).
 * docs/uncertainty.md gives the estimators, their sources and how to read
 * them. */
#ifndef POSEDROP_SENSITIVITY_H
#define POSEDROP_SENSITIVITY_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/sim.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Bootstrap resamples behind an index's interval. */
#define PD_SENSITIVITY_RESAMPLES 200

/* The first-order index of y with respect to x from n given pairs (any
 * distribution of x; y real, e.g. an indicator): the drops sorted by x and
 * cut into M = ceil(sqrt(n)) bins of equal count (at most 100), and
 *     S = (SSB - (M - 1) SSW / (n - M)) / SST,
 * the between-bin sum of squares of y less its expectation when y does not
 * depend on x (the one-way analysis of variance's correction), over the
 * total sum of squares. *index is S clipped to [0, 1]; *lo, *hi its 95%
 * percentile interval over PD_SENSITIVITY_RESAMPLES resamples of the pairs
 * (drawn from seed: the same data and seed, the same bytes), clipped the
 * same way. A y that does not vary gives 0 and [0, 0]. PD_ERR_USAGE for n
 * below 4 or a NULL pointer, PD_ERR_NONFINITE for a NaN or infinity,
 * PD_ERR_NOMEM. */
PD_API pd_status pd_first_order_index(const double *x, const double *y, long n, uint64_t seed,
                                      double *index, double *lo, double *hi, pd_diag *diag);

/* One pose (or class) and one ranged parameter. */
typedef struct pd_sensitivity_row {
    int pose;               /* 0-based: a pose of the result, or a class with class_of */
    pd_scene_param param;
    double effect, effect_lo, effect_hi; /* p_high - p_low: how far the pose moves
                                            across the range, in probability (0.05:
                                            5 points), and its 95% percentile
                                            interval over PD_SENSITIVITY_RESAMPLES
                                            resamples of the drops */
    int interacts;          /* -1, or the parameter (pd_scene_param) across
                               whose thirds this effect changes: its effect in
                               two of that parameter's thirds differ by more
                               than their joint interval (z 2.39, the 95%
                               two-sided point shared by the three pairs of
                               thirds, Bonferroni) */
    double effect_in[3];    /* with interacts: the effect among the drops in
                               that parameter's lower, middle, upper third */
    double interaction, interaction_lo, interaction_hi; /* with interacts: the
                               largest difference of effect_in, the later third's
                               less the earlier's, and its interval */
    long n_low, n_high;     /* settled drops whose value fell in the lower,
                               upper third of the range (by its distribution:
                               thirds of log for log uniform) */
    double p_low, p_low_lo, p_low_hi;    /* the pose's share of them, 95% Wilson */
    double p_high, p_high_lo, p_high_hi;
    double index, index_lo, index_hi;    /* S_i and its 95% bootstrap interval */
} pd_sensitivity_row;

typedef struct pd_sensitivity {
    long n;                 /* drops used: settled ones, and of a stationary
                               run only those started uniform */
    int nposes;             /* poses (or classes) */
    int nparams;            /* ranged parameters, in pd_scene_param order */
    pd_scene_param param[PD_NPARAMS];
    pd_sensitivity_row *rows; /* nposes * nparams, pose-major */
    double resolution;      /* the largest half-width of an effect's interval:
                               an effect smaller than this the run could not
                               tell from none (0 without rows) */
    int interaction_tests;  /* pose and ordered parameter pairs tested for an
                               interaction: about 5% of them are flagged by
                               chance alone */
} pd_sensitivity;

/* The sensitivity of a run made with keep_trials from scene (the scene given
 * to pd_sim_run; part_size the part's pd_contact_time_auto_size, for
 * contact_time in multiples of auto). class_of (result->nposes entries) groups the poses into nclasses
 * classes, as pd_pose_classes gives them; NULL for poses. Every ranged
 * parameter of nonzero width gets a row per pose; a scene without one gives
 * nparams 0. PD_ERR_USAGE (NULL, no trial records, a class out of range),
 * PD_ERR_NOMEM. *out is the caller's (pd_sensitivity_free). */
PD_API pd_status pd_sim_sensitivity(const pd_sim_result *result, const pd_scene *scene,
                                    double part_size, const int *class_of, int nclasses,
                                    pd_sensitivity **out, pd_diag *diag);

PD_API void pd_sensitivity_free(pd_sensitivity *sensitivity);

#ifdef __cplusplus
}
#endif
#endif
