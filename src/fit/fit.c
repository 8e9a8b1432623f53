/* fit.c: pd_fit_run, the fit of scene parameters to measured drops, with
 * posedrop's own drops as the model (docs/calibration.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/gsl_adapter.h"
#include "fit/fit_engine.h"
#include "posedrop/fit.h"
#include "posedrop/symmetry.h"
#include "posedrop/tolerances.h"

void pd_fit_options_default(pd_fit_options *o)
{
    if (!o)
        return;
    memset(o, 0, sizeof *o);
    o->ndrops = 1000;
    o->seed = 1;
    o->threads = 0;
    o->engine = PD_ENGINE_IMPULSE;
    o->fit_initial = 0;
    o->max_evals = 150;
    o->npoints = 0;
    o->alpha = 0.5;
}

/* The keys a fit may vary: the numeric ones of pd_scene_set. */
static const char *const fit_keys[] = {"height", "belt_speed", "mu", "restitution", "vibration",
                                       "gravity", "contact_time", "tumble"};

typedef struct {
    const pd_fit_part *parts;
    const long **count; /* per part: the counts the current search uses (NULL: not fitted) */
    int nparts;
    const pd_fit_param *params;
    int d;
    pd_scene base;
    pd_sim_options sim;
    long *ndrops;  /* per part, at FIT_LEVEL_FULL */
    long *need;    /* per part: the fewest drops its initial mode runs */
    int *nsym;     /* per part: its classes of symmetric poses (the stationary chain's states) */
    long drops;    /* simulated so far */
    long failed;   /* of them, drops that failed */
    double *pose_p; /* scratch, the largest part's poses */
    /* The last point simulated at FIT_LEVEL_FULL and the parts simulated
     * there (memo_have), so that the search's best point, evaluated again
     * with every part by the weighting, runs only the parts it has not. */
    double memo_theta[PD_FIT_MAX_PARAMS];
    int *memo_have;
    double **memo_p, *memo_nsim;
    pd_fit_progress_fn progress;
    void *progress_user;
    pd_fit_progress prog;
} model;

/* Two points closer than this relative to their size are the same point:
 * a few units of round-off of theta -> z -> theta. */
static const double MEMO_ROUNDOFF = 1e-13;

/* The seeds of FIT_LEVEL_FULL and of the fresh drops: any but the search's
 * own, and not each other. */
static const uint64_t FULL_SEED = 0x6a09e667f3bcc908u, FRESH_SEED = 0x9e3779b97f4a7c15u;

static const char *mode_name(pd_initial i)
{
    return i == PD_INITIAL_BOOTSTRAP ? "bootstrap" : i == PD_INITIAL_STATIONARY ? "stationary"
                                                                              : "uniform";
}

/* The engine's note after each evaluation, passed on as pd_fit_progress. */
static void note(void *user, const char *stage, int round, double loglik)
{
    model *m = user;
    pd_fit_progress *g = &m->prog;
    if (strcmp(stage, g->stage) != 0 || round != g->round)
        g->best_loglik = -HUGE_VAL;
    g->stage = stage;
    g->round = round;
    g->evaluation++;
    g->drops = m->drops;
    /* A prediction or a fresh check is not the search's likelihood. */
    int scored = strcmp(stage, "prediction") != 0 && strcmp(stage, "fresh") != 0;
    if (scored && loglik > g->best_loglik)
        g->best_loglik = loglik;
    if (m->progress)
        m->progress(g, m->progress_user);
}

/* Drops per part for an initial mode: the stationary start, on the chain of
 * classes of symmetric poses, needs PD_STATIONARY_MIN_POSE_DROPS per class
 * and as many uniform ones. */
static void set_ndrops(model *m, long ndrops, pd_initial mode)
{
    m->base.initial = mode;
    for (int i = 0; m->memo_have && i < m->nparts; i++)
        m->memo_have[i] = 0;
    for (int i = 0; i < m->nparts; i++) {
        m->need[i] = mode == PD_INITIAL_STATIONARY
                         ? (long)(m->nsym[i] + 1) * PD_STATIONARY_MIN_POSE_DROPS
                         : 10;
        m->ndrops[i] = ndrops > m->need[i] ? ndrops : m->need[i];
    }
}

/* Part i's drops at a level: the search and the weighting's points a
 * quarter of the full drops (at least what the mode needs). */
static long level_drops(const model *m, int i, fit_level level)
{
    long n = level == FIT_LEVEL_SEARCH || level == FIT_LEVEL_WEIGH || level >= FIT_LEVEL_REPEAT
                 ? m->ndrops[i] / 4
                 : m->ndrops[i];
    return n > m->need[i] ? n : m->need[i];
}

static uint64_t level_seed(const model *m, fit_level level)
{
    /* The repeats' seeds: the full level's, moved by a multiple of an odd
     * constant (the golden ratio's) that no other level's equals. */
    if (level >= FIT_LEVEL_REPEAT)
        return m->sim.seed ^ FULL_SEED ^
               (0x9e3779b97f4a7c15u * (uint64_t)(level - FIT_LEVEL_REPEAT + 2));
    return level == FIT_LEVEL_FRESH                                  ? m->sim.seed ^ FRESH_SEED
           : level == FIT_LEVEL_FULL || level == FIT_LEVEL_WEIGH ? m->sim.seed ^ FULL_SEED
                                                                 : m->sim.seed;
}

/* A value of q as pd_scene_set reads it: a multiple of auto as the
 * zero-width range "Mx:Mx", which every drop of every part draws as M times
 * that part's own automatic duration (the fixed run's bytes for that
 * duration). */
static void param_text(const pd_fit_param *q, double v, char *text, size_t size)
{
    if (q->multiple)
        snprintf(text, size, "%.17gx:%.17gx", v, v);
    else
        snprintf(text, size, "%.17g", v);
}

/* The scene at theta (in the problem's scale: log for a log parameter). */
static pd_status scene_at(const model *m, const double *theta, pd_scene *sc, pd_diag *diag)
{
    *sc = m->base;
    for (int i = 0; i < m->d; i++) {
        char text[80];
        param_text(&m->params[i], m->params[i].log ? exp(theta[i]) : theta[i], text, sizeof text);
        pd_status st = pd_scene_set(sc, m->params[i].key, text, diag);
        if (st != PD_OK)
            return st;
    }
    return PD_OK;
}

static int cancelled(const pd_sim_options *o)
{
    return o->cancel && atomic_load(o->cancel) != 0;
}

static pd_status run_model(void *user, const double *theta, int all, fit_level level,
                           double *const *p, double *nsim, pd_diag *diag)
{
    model *m = user;
    pd_scene sc;
    if (cancelled(&m->sim))
        return pd_fail(diag, PD_ERR_CANCELLED, "pd_fit_run: cancelled");
    pd_status st = scene_at(m, theta, &sc, diag);
    int memo = level == FIT_LEVEL_FULL, same = 1;
    /* The weighting gets the best point back through the unit cube: the
     * same point to a few units of round-off. */
    for (int j = 0; j < m->d; j++)
        same &= fabs(theta[j] - m->memo_theta[j]) <=
                MEMO_ROUNDOFF * (fabs(theta[j]) + fabs(m->memo_theta[j]));
    if (memo && !same) {
        memcpy(m->memo_theta, theta, sizeof *theta * (size_t)m->d);
        for (int i = 0; i < m->nparts; i++)
            m->memo_have[i] = 0;
    }
    for (int i = 0; st == PD_OK && i < m->nparts; i++) {
        const pd_fit_part *fp = &m->parts[i];
        if ((all == 0 && !m->count[i]) || (all == 2 && m->count[i]))
            continue;
        if (memo && m->memo_have[i]) { /* the same drops: the same counts */
            memcpy(p[i], m->memo_p[i], sizeof **p * (size_t)fp->nclasses);
            nsim[i] = m->memo_nsim[i];
            continue;
        }
        pd_sim_options o = m->sim;
        o.ndrops = level_drops(m, i, level);
        o.seed = level_seed(m, level);
        pd_sim_result *r = NULL;
        if ((st = pd_sim_run(fp->part, fp->poses, &sc, &o, &r, diag)) != PD_OK)
            break;
        /* Stopped part way: its counts are not those of the fixed drops. */
        if (r->partial) {
            pd_sim_result_free(r);
            st = pd_fail(diag, PD_ERR_CANCELLED, "pd_fit_run: cancelled");
            break;
        }
        m->drops += r->n;
        m->failed += r->failed;
        /* No drop ran to an end the model defines: the likelihood would be
         * the smoothing's alone, flat, and its optimum meaningless. */
        if (r->n > 0 && r->failed == r->n) {
            char st_name[64];
            snprintf(st_name, sizeof st_name, "%s", pd_status_str(r->failed_status));
            st = pd_fail(diag, PD_ERR_NO_CONVERGENCE, "every one of the %ld simulated drops of "
                         "part %d failed (the first at stage %s: %s): no likelihood to fit", r->n,
                         i + 1, pd_drop_stage_name(r->failed_stage), st_name);
            pd_sim_result_free(r);
            break;
        }
        long settled = r->n - r->unsettled;
        int chain = r->transitions && r->closed_classes > 0;
        for (int j = 0; j < r->nposes; j++)
            m->pose_p[j] = chain ? r->p[j] : settled ? (double)r->count[j] / (double)settled : 0.0;
        for (int c = 0; c < fp->nclasses; c++)
            p[i][c] = 0.0;
        double sum = 0.0;
        for (int j = 0; j < r->nposes; j++) {
            p[i][fp->class_of ? fp->class_of[j] : j] += m->pose_p[j];
            sum += m->pose_p[j];
        }
        /* No drop settled: nothing is known, and the smoothing alone speaks. */
        for (int c = 0; c < fp->nclasses; c++)
            p[i][c] = sum > 0 ? p[i][c] / sum : 1.0 / fp->nclasses;
        nsim[i] = sum > 0 ? (double)settled : 0.0;
        pd_sim_result_free(r);
        if (memo) {
            memcpy(m->memo_p[i], p[i], sizeof **p * (size_t)fp->nclasses);
            m->memo_nsim[i] = nsim[i];
            m->memo_have[i] = 1;
        }
    }
    return st;
}

static pd_status check_parts(const pd_fit_part *parts, int nparts, pd_diag *diag)
{
    int fitted = 0;
    if (!parts || nparts < 1)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: no part given");
    for (int i = 0; i < nparts; i++) {
        const pd_fit_part *fp = &parts[i];
        if (!fp->part || !fp->poses || fp->poses->nposes < 1)
            return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d has no part or no stable pose",
                           i + 1);
        int k = fp->class_of ? fp->nclasses : fp->poses->nposes;
        if (fp->nclasses != k || k < 1)
            return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: %d classes given for %d "
                           "poses%s", i + 1, fp->nclasses, fp->poses->nposes,
                           fp->class_of ? "" : " without class_of (expected one per pose)");
        for (int j = 0; fp->class_of && j < fp->poses->nposes; j++)
            if (fp->class_of[j] < 0 || fp->class_of[j] >= k)
                return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: pose %d in class %d, "
                               "outside 1..%d", i + 1, j + 1, fp->class_of[j] + 1, k);
        for (int c = 0; fp->class_of && c < k; c++) {
            int members = 0;
            for (int j = 0; j < fp->poses->nposes; j++)
                members += fp->class_of[j] == c;
            if (!members)
                return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: class %d has no pose",
                               i + 1, c + 1);
        }
        if (!fp->count)
            continue;
        int ncells = fp->cell_of ? fp->ncells : k;
        if (fp->cell_of) {
            if (ncells < 1 || ncells > k)
                return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: %d cells of counts for "
                               "%d classes: expected 1 to %d", i + 1, ncells, k, k);
            for (int c = 0; c < k; c++)
                if (fp->cell_of[c] < 0 || fp->cell_of[c] >= ncells)
                    return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: class %d counted in "
                                   "cell %d, outside 1..%d", i + 1, c + 1, fp->cell_of[c] + 1,
                                   ncells);
            for (int j = 0; j < ncells; j++) {
                int members = 0;
                for (int c = 0; c < k; c++)
                    members += fp->cell_of[c] == j;
                if (!members)
                    return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: cell %d of counts "
                                   "has no class", i + 1, j + 1);
            }
        }
        long n = 0;
        for (int c = 0; c < ncells; c++) {
            if (fp->count[c] < 0)
                return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: class %d has a negative "
                               "count (%ld)", i + 1, c + 1, fp->count[c]);
            if (fp->count[c] > PD_FIT_MAX_COUNT - n)
                return pd_fail(diag, PD_ERR_RANGE, "pd_fit_run: part %d: the counts add up to "
                               "more than %.0e drops, more than were ever measured", i + 1,
                               (double)PD_FIT_MAX_COUNT);
            n += fp->count[c];
        }
        if (n == 0)
            return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: part %d: its counts add up to 0",
                           i + 1);
        fitted++;
    }
    if (!fitted)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: no part has measured counts to fit");
    return PD_OK;
}

static pd_status check_params(const pd_fit_param *params, int d, const pd_scene *base,
                              pd_diag *diag)
{
    if (!params)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: NULL params");
    if (d < 1 || d > PD_FIT_MAX_PARAMS)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: %d parameters to fit: expected 1 to %d",
                       d, PD_FIT_MAX_PARAMS);
    for (int i = 0; i < d; i++) {
        const pd_fit_param *q = &params[i];
        int known = 0;
        for (size_t j = 0; q->key && j < sizeof fit_keys / sizeof fit_keys[0]; j++)
            known |= strcmp(q->key, fit_keys[j]) == 0;
        if (!known)
            return pd_fail(diag, PD_ERR_USAGE, "cannot fit '%s': expected one of height, "
                           "belt_speed, mu, restitution, vibration, gravity, contact_time, "
                           "tumble",
                           q->key ? q->key : "(null)");
        for (int j = 0; j < i; j++)
            if (strcmp(q->key, params[j].key) == 0)
                return pd_fail(diag, PD_ERR_USAGE, "%s is to be fitted twice", q->key);
        if (!isfinite(q->lo) || !isfinite(q->hi))
            return pd_fail(diag, PD_ERR_NONFINITE, "%s: the range %g:%g is not finite", q->key,
                           q->lo, q->hi);
        if (!(q->lo < q->hi))
            return pd_fail(diag, PD_ERR_USAGE, "%s: the range %g:%g is empty: expected LO < HI",
                           q->key, q->lo, q->hi);
        if (q->log && !(q->lo > 0))
            return pd_fail(diag, PD_ERR_USAGE, "%s: a log range needs LO > 0, got %g", q->key,
                           q->lo);
        if (q->multiple != 0 && (q->multiple != 1 || strcmp(q->key, "contact_time") != 0))
            return pd_fail(diag, PD_ERR_USAGE, "%s: multiple is %d: expected 0%s", q->key,
                           q->multiple, strcmp(q->key, "contact_time") == 0
                                            ? " or 1"
                                            : " (only contact_time takes multiples of auto)");
        /* Both ends must be values the scene accepts. */
        pd_scene sc = *base;
        char text[80];
        for (int e = 0; e < 2; e++) {
            param_text(q, e ? q->hi : q->lo, text, sizeof text);
            pd_status st = pd_scene_set(&sc, q->key, text, diag);
            if (st != PD_OK)
                return st;
        }
    }
    return PD_OK;
}

static pd_status check_options(const pd_fit_options *o, pd_diag *diag)
{
    if (o->ndrops < 10)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: %ld drops per evaluation: expected at "
                       "least 10", o->ndrops);
    if (o->max_evals < 1 || o->npoints < 0 || o->threads < 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: max_evals %d, npoints %d, threads %d: "
                       "expected max_evals >= 1, npoints >= 0, threads >= 0", o->max_evals,
                       o->npoints, o->threads);
    if (!(o->alpha > 0) || !isfinite(o->alpha))
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: alpha %g: expected a positive pseudo-count",
                       o->alpha);
    if (o->fit_initial != 0 && o->fit_initial != 1)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: fit_initial %d: expected 0 or 1",
                       o->fit_initial);
    return PD_OK;
}

void pd_fit_result_free(pd_fit_result *r)
{
    if (!r)
        return;
    free(r->value);
    free(r->lo);
    free(r->hi);
    free(r->mean);
    for (int i = 0; r->parts && i < r->nparts; i++) {
        free(r->parts[i].p_best);
        free(r->parts[i].p);
        free(r->parts[i].lo);
        free(r->parts[i].hi);
        free(r->parts[i].lo_fit);
        free(r->parts[i].hi_fit);
    }
    free(r->parts);
    free(r);
}

static pd_fit_result *result_alloc(int d, const pd_fit_part *parts, int nparts)
{
    pd_fit_result *r = calloc(1, sizeof *r);
    if (!r)
        return NULL;
    r->nparams = d;
    r->nparts = nparts;
    r->value = calloc((size_t)d, sizeof *r->value);
    r->lo = calloc((size_t)d, sizeof *r->lo);
    r->hi = calloc((size_t)d, sizeof *r->hi);
    r->mean = calloc((size_t)d, sizeof *r->mean);
    r->parts = calloc((size_t)nparts, sizeof *r->parts);
    int ok = r->value && r->lo && r->hi && r->mean && r->parts;
    for (int i = 0; ok && i < nparts; i++) {
        pd_fit_part_result *q = &r->parts[i];
        size_t k = (size_t)parts[i].nclasses;
        q->nclasses = parts[i].nclasses;
        q->p_best = calloc(k, sizeof *q->p_best);
        q->p = calloc(k, sizeof *q->p);
        q->lo = calloc(k, sizeof *q->lo);
        q->hi = calloc(k, sizeof *q->hi);
        q->lo_fit = calloc(k, sizeof *q->lo_fit);
        q->hi_fit = calloc(k, sizeof *q->hi_fit);
        ok = q->p_best && q->p && q->lo && q->hi && q->lo_fit && q->hi_fit;
    }
    if (!ok) {
        pd_fit_result_free(r);
        return NULL;
    }
    return r;
}

/* Pearson's X^2 of the 2 x K table of counts (n of them, per cell) and
 * simulated frequencies p (per class) of nsim drops, the cells neither
 * reached left out; the TV distance of their frequencies. */
static pd_fit_quality quality(int k, const int *cell_of, int ncells, const long *count,
                              const double *p, double nsim)
{
    pd_fit_quality q = {0.0, 0, 1.0, 0.0};
    long n = 0;
    for (int c = 0; c < ncells; c++)
        n += count[c];
    q.chi2 = fit_chi2_two_sample(k, cell_of, ncells, count, p, nsim, &q.df);
    for (int c = 0; n > 0 && c < ncells; c++)
        q.tv += 0.5 * fabs((double)count[c] / (double)n - fit_cell_p(k, cell_of, c, p));
    q.pvalue = q.df > 0 ? pd_gsl_chisq_q(q.chi2, q.df) : 1.0;
    return q;
}

/* Part i's cells of counts (its classes when it has no cell_of). */
static int part_cells(const pd_fit_part *fp)
{
    return fp->cell_of ? fp->ncells : fp->nclasses;
}

/* Each fitted part's fresh-drop quality at theta (the problem's scale), and
 * all parts' together (df less the d fitted parameters). */
static pd_status fresh(model *m, const fit_problem *pb, const double *theta,
                       double *const *p, double *nsim, pd_fit_result *r, int at_mean,
                       pd_diag *diag)
{
    m->prog.stage = "fresh";
    pd_status st = run_model(m, theta, 0, FIT_LEVEL_FRESH, p, nsim, diag);
    if (st != PD_OK)
        return st;
    note(m, "fresh", 0, 0.0);
    r->evaluations++;
    pd_fit_quality all = {0.0, -m->d, 1.0, 0.0};
    long ntot = 0;
    for (int i = 0; i < m->nparts; i++) {
        if (!pb->count[i])
            continue;
        const pd_fit_part *fp = &m->parts[i];
        pd_fit_quality q = quality(pb->k[i], fp->cell_of, part_cells(fp), pb->count[i], p[i],
                                   nsim[i]);
        long n = 0;
        for (int c = 0; c < part_cells(fp); c++)
            n += pb->count[i][c];
        all.chi2 += q.chi2;
        all.df += q.df;
        all.tv += (double)n * q.tv; /* count-weighted mean */
        ntot += n;
        if (at_mean)
            r->parts[i].fresh_mean = q;
        else
            r->parts[i].fresh_best = q;
    }
    all.tv /= (double)ntot;
    all.pvalue = all.df > 0 ? pd_gsl_chisq_q(all.chi2, all.df) : 1.0;
    if (at_mean)
        r->fresh_mean = all;
    else
        r->fresh_best = all;
    return PD_OK;
}

/* Every search's most evaluations: the design, the simplex and its last
 * step, and its finalists on the full drops. */
static int search_max_evals(int d, int max_evals)
{
    return 4 * d + 1 + max_evals + d + 1 + FIT_FINALISTS;
}

pd_status pd_fit_run(const pd_fit_part *parts, int nparts, const pd_fit_param *params,
                     int nparams, const pd_scene *base, const pd_fit_options *options,
                     pd_fit_result **result, pd_diag *diag)
{
    pd_fit_options o;
    pd_scene sc0;
    if (!options || !result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_fit_run: NULL %s", options ? "result" : "options");
    o = *options;
    if (base)
        sc0 = *base;
    else
        pd_scene_default(&sc0);
    pd_status st = check_options(&o, diag);
    if (st == PD_OK)
        st = check_parts(parts, nparts, diag);
    if (st == PD_OK)
        st = pd_scene_check(&sc0, diag);
    if (st == PD_OK)
        st = check_params(params, nparams, &sc0, diag);
    if (st != PD_OK)
        return st;
    int d = nparams, maxposes = 1, nfit = 0;
    for (int i = 0; i < nparts; i++) {
        maxposes = parts[i].poses->nposes > maxposes ? parts[i].poses->nposes : maxposes;
        nfit += parts[i].count != NULL;
    }
    model m = {.parts = parts, .nparts = nparts, .params = params, .d = d, .base = sc0,
               .progress = o.progress, .progress_user = o.progress_user};
    pd_sim_options_default(&m.sim);
    m.sim.seed = o.seed;
    m.sim.threads = o.threads;
    m.sim.engine = o.engine;
    m.sim.cancel = o.cancel;
    m.sim.stationary_by_class = 1;
    m.memo_have = calloc((size_t)nparts, sizeof *m.memo_have);
    m.memo_p = calloc((size_t)nparts, sizeof *m.memo_p);
    m.memo_nsim = calloc((size_t)nparts, sizeof *m.memo_nsim);
    for (int i = 0; m.memo_p && i < nparts; i++)
        m.memo_p[i] = malloc(sizeof **m.memo_p * (size_t)parts[i].nclasses);
    m.ndrops = malloc(sizeof *m.ndrops * (size_t)nparts);
    m.need = malloc(sizeof *m.need * (size_t)nparts);
    m.nsym = malloc(sizeof *m.nsym * (size_t)nparts);
    int *sym_of = malloc(sizeof *sym_of * (size_t)maxposes);
    m.pose_p = malloc(sizeof *m.pose_p * (size_t)maxposes);
    double lo[PD_FIT_MAX_PARAMS], hi[PD_FIT_MAX_PARAMS];
    int *kk = malloc(sizeof *kk * (size_t)nparts);
    const long **count = malloc(sizeof *count * (size_t)nparts);
    const long **one = malloc(sizeof *one * (size_t)nparts);
    const int **cell_of = malloc(sizeof *cell_of * (size_t)nparts);
    int *ncells = malloc(sizeof *ncells * (size_t)nparts);
    pd_fit_result *r = result_alloc(d, parts, nparts);
    double **pb_best = malloc(sizeof *pb_best * (size_t)nparts);
    double **pp = malloc(sizeof *pp * (size_t)nparts), **plo = malloc(sizeof *plo * (size_t)nparts);
    double **phi = malloc(sizeof *phi * (size_t)nparts), *nsim = malloc(sizeof *nsim * (size_t)nparts);
    double **plo_fit = malloc(sizeof *plo_fit * (size_t)nparts);
    double **phi_fit = malloc(sizeof *phi_fit * (size_t)nparts);
    /* The model's output outside the result: the held-out predictions and
     * the fresh drops. */
    double **ps = malloc(sizeof *ps * (size_t)nparts), *ns = malloc(sizeof *ns * (size_t)nparts);
    size_t ksum = 0;
    for (int i = 0; i < nparts; i++)
        ksum += (size_t)parts[i].nclasses;
    double *pbuf = malloc(sizeof *pbuf * ksum);
    int memo_ok = m.memo_have && m.memo_p && m.memo_nsim;
    for (int i = 0; memo_ok && i < nparts; i++)
        memo_ok = m.memo_p[i] != NULL;
    if (!memo_ok || !m.ndrops || !m.need || !m.nsym || !sym_of || !m.pose_p || !kk || !count || !one || !cell_of || !ncells || !r || !pb_best || !pp || !plo || !phi ||
        !plo_fit || !phi_fit || !nsim || !ps || !ns || !pbuf) {
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the fit");
        goto done;
    }
    m.count = count;
    for (int i = 0; st == PD_OK && i < nparts; i++)
        st = pd_pose_classes(parts[i].part, parts[i].poses, sym_of, &m.nsym[i], diag);
    if (st != PD_OK)
        goto done;
    for (int i = 0; i < d; i++) {
        lo[i] = params[i].log ? log(params[i].lo) : params[i].lo;
        hi[i] = params[i].log ? log(params[i].hi) : params[i].hi;
    }
    for (int i = 0; i < nparts; i++) {
        kk[i] = parts[i].nclasses;
        count[i] = parts[i].count;
        cell_of[i] = parts[i].cell_of;
        ncells[i] = part_cells(&parts[i]);
        pb_best[i] = r->parts[i].p_best;
        pp[i] = r->parts[i].p;
        plo[i] = r->parts[i].lo;
        phi[i] = r->parts[i].hi;
        plo_fit[i] = r->parts[i].lo_fit;
        phi_fit[i] = r->parts[i].hi_fit;
        ps[i] = i ? ps[i - 1] + kk[i - 1] : pbuf;
    }
    fit_problem pb = {d,      lo,      hi,        nparts,    kk,   count, cell_of,
                      ncells, o.alpha, run_model, &m, note, &m};
    fit_settings set = {o.max_evals, o.npoints ? o.npoints : 8 * (d + 1)};
    double theta[PD_FIT_MAX_PARAMS], best_theta[PD_FIT_MAX_PARAMS], best = -HUGE_VAL;
    pd_initial modes[3] = {PD_INITIAL_UNIFORM, PD_INITIAL_BOOTSTRAP, PD_INITIAL_STATIONARY};
    int nmodes = o.fit_initial ? 3 : 1;
    if (!o.fit_initial)
        modes[0] = sc0.initial;
    /* With two or more fitted parts the mode is chosen by how well a fit to
     * all parts but one predicts the one left out: the in-sample likelihood
     * ranks the modes by how they absorb the fitted parts' misfit. */
    int holdout = o.fit_initial && nfit >= 2;
    r->initial_untested = o.fit_initial && nfit < 2;
    for (int i = 0; i < 3; i++)
        r->loglik_initial[i] = -HUGE_VAL;
    /* The plan, before the first evaluation. */
    int searches = nmodes * (holdout ? nfit + 1 : 1) - (holdout ? nmodes - 1 : 0);
    /* Drops per evaluation at each level, the fitted parts' and the
     * predicted ones', for the costliest mode (the stationary start needs
     * the most). */
    set_ndrops(&m, o.ndrops, o.fit_initial ? PD_INITIAL_STATIONARY : sc0.initial);
    long per[FIT_LEVEL_FRESH + 1] = {0}, pred = 0;
    for (int i = 0; i < nparts; i++)
        for (int l = 0; l <= FIT_LEVEL_FRESH; l++) {
            if (parts[i].count)
                per[l] += level_drops(&m, i, (fit_level)l);
            else if (l == FIT_LEVEL_FULL)
                pred += level_drops(&m, i, FIT_LEVEL_FULL);
        }
    int weigh_points = fit_weigh_max_evals(&set) - 1 - FIT_PREDICT_ROUNDS * set.npoints;
    m.prog = (pd_fit_progress){"start", mode_name(modes[0]), 0, 0, 0, 0, 0, 0, -HUGE_VAL};
    m.prog.max_evaluations = searches * search_max_evals(d, o.max_evals) +
                             (holdout ? nmodes * nfit : 0) + fit_weigh_max_evals(&set) + 2;
    m.prog.max_drops = searches * ((4 * d + 1 + o.max_evals + d + 1) * per[FIT_LEVEL_SEARCH] +
                                   FIT_FINALISTS * per[FIT_LEVEL_FULL]) +
                       (holdout ? nmodes * nfit : 0) * per[FIT_LEVEL_FULL] +
                       per[FIT_LEVEL_FULL] + pred + weigh_points * per[FIT_LEVEL_WEIGH] +
                       FIT_PREDICT_ROUNDS * set.npoints * pred + 2 * per[FIT_LEVEL_FRESH];
    if (m.progress)
        m.progress(&m.prog, m.progress_user);
    pd_initial chosen = modes[0];
    for (int mi = 0; st == PD_OK && mi < nmodes; mi++) {
        set_ndrops(&m, o.ndrops, modes[mi]);
        m.prog.initial = mode_name(modes[mi]);
        double l, score = 0.0;
        for (int j = 0; holdout && st == PD_OK && j < nparts; j++) {
            if (!parts[j].count)
                continue;
            /* The search without part j, then part j's counts at its maximum
             * (the Dirichlet-multinomial, as the search weighs them). */
            count[j] = NULL;
            m.prog.held_out = j + 1;
            st = fit_search(&pb, &set, theta, &l, &r->evaluations, diag);
            count[j] = parts[j].count;
            for (int i = 0; i < nparts; i++)
                one[i] = i == j ? parts[j].count : NULL;
            m.count = one;
            if (st == PD_OK)
                st = run_model(&m, theta, 0, FIT_LEVEL_FULL, ps, ns, diag);
            m.count = count;
            if (st == PD_OK) {
                r->evaluations++;
                note(&m, "prediction", 0, 0.0);
                score += fit_loglik_cells(kk[j], cell_of[j], ncells[j], parts[j].count, ps[j],
                                          ns[j], o.alpha);
            }
        }
        m.prog.held_out = 0;
        if (st != PD_OK)
            break;
        if (holdout) {
            r->loglik_initial[modes[mi]] = score;
            if (score > best) {
                best = score;
                chosen = modes[mi];
            }
            continue;
        }
        st = fit_search(&pb, &set, theta, &l, &r->evaluations, diag);
        if (st != PD_OK)
            break;
        r->loglik_initial[modes[mi]] = l;
        if (l > best) {
            best = l;
            chosen = modes[mi];
            memcpy(best_theta, theta, sizeof theta[0] * (size_t)d);
        }
    }
    set_ndrops(&m, o.ndrops, chosen);
    m.prog.initial = mode_name(chosen);
    if (st == PD_OK && holdout) {
        double l;
        st = fit_search(&pb, &set, best_theta, &l, &r->evaluations, diag);
    }
    if (st != PD_OK)
        goto done;
    fit_weighed w = {r->lo,  r->hi, r->mean, pb_best, nsim,    pp,
                     plo,    phi,   1.0,     0.0,     0,       0.0,
                     plo_fit, phi_fit, 0.0, 0.0};
    st = fit_weigh(&pb, &set, best_theta, &w, &r->evaluations, diag);
    if (st == PD_OK) {
        r->loglik = 0.0;
        r->chi2 = 0.0;
        r->df = -d;
        for (int i = 0; i < nparts; i++) {
            pd_fit_part_result *q = &r->parts[i];
            q->nsim = (long)nsim[i];
            q->df = ncells[i] - 1;
            if (!parts[i].count)
                continue;
            for (int c = 0; c < ncells[i]; c++)
                q->n += parts[i].count[c];
            for (int c = 0; c < ncells[i]; c++) {
                double pc = fit_cell_p(kk[i], cell_of[i], c, q->p_best);
                if (parts[i].count[c] > 0)
                    q->loglik += (double)parts[i].count[c] * log(pc);
                q->tv += 0.5 * fabs((double)parts[i].count[c] / (double)q->n - pc);
            }
            /* X^2 of the 2 x K table of the counts and the best point's drops
             * (their frequencies, the smoothing undone), the statistic the
             * dispersion and the fresh-drop check use: against the smoothed
             * probabilities, a class of many counts that no drop reached
             * gives a term of hundreds. */
            for (int c = 0; c < kk[i]; c++) {
                double f = nsim[i] > 0 ? (q->p_best[c] * (nsim[i] + kk[i] * o.alpha) - o.alpha) /
                                             nsim[i]
                                       : 0.0;
                ps[i][c] = f > 0 ? f : 0.0;
            }
            q->chi2 = fit_chi2_two_sample(kk[i], cell_of[i], ncells[i], parts[i].count, ps[i],
                                          nsim[i], &q->df);
            q->pvalue = q->df > 0 ? pd_gsl_chisq_q(q->chi2, q->df) : 1.0;
            r->loglik += q->loglik;
            r->chi2 += q->chi2;
            r->df += q->df;
        }
        r->pvalue = r->df > 0 ? pd_gsl_chisq_q(r->chi2, r->df) : 1.0;
        r->initial = chosen;
        r->dispersion = w.dispersion;
        r->discrepancy = w.discrepancy;
        r->ess = w.ess;
        r->weigh_noise_sd = w.noise_sd;
        r->weigh_misfit_sd = w.misfit_sd;
        r->npoints = w.npoints;
        /* The fit's quality from drops it was not tuned to, at the best
         * values and at the weighted means. */
        st = fresh(&m, &pb, best_theta, ps, ns, r, 0, diag);
        if (st == PD_OK)
            st = fresh(&m, &pb, r->mean, ps, ns, r, 1, diag);
    }
    if (st == PD_OK) {
        for (int i = 0; i < d; i++) {
            r->value[i] = best_theta[i];
            if (params[i].log) {
                r->value[i] = exp(r->value[i]);
                r->lo[i] = exp(r->lo[i]);
                r->hi[i] = exp(r->hi[i]);
                r->mean[i] = exp(r->mean[i]);
            }
        }
        st = scene_at(&m, best_theta, &r->scene, diag);
        r->drops = m.drops;
        r->failed = m.failed;
    }
done:
    free(pb_best);
    free(pp);
    free(plo);
    free(phi);
    free(plo_fit);
    free(phi_fit);
    free(nsim);
    free(ps);
    free(ns);
    free(pbuf);
    for (int i = 0; m.memo_p && i < nparts; i++)
        free(m.memo_p[i]);
    free(m.memo_p);
    free(m.memo_have);
    free(m.memo_nsim);
    free(m.ndrops);
    free(m.need);
    free(m.nsym);
    free(sym_of);
    free(m.pose_p);
    free(kk);
    free(count);
    free(one);
    free(cell_of);
    free(ncells);
    if (st == PD_OK)
        *result = r;
    else
        pd_fit_result_free(r);
    return st;
}
