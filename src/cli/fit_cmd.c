/* fit_cmd.c: posedrop fit, the scene calibrated to measured drops
 * (pd_fit_run; docs/calibration.md). */
#include <errno.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/number.h"
#include "cli/cli.h"

enum { MAX_PARTS = 64 };
/* Fewer effective weighted values than this leave the 2.5% and 97.5%
 * quantiles to one or two points each. */
static const double FEW_EFFECTIVE = 10.0;
/* An interval spanning more than this share of its range (on the scale
 * searched): the data do not pin the parameter down. */
static const double UNIDENTIFIED_SHARE = 0.8;
/* A progress line at most this often, s of wall time: a fit's evaluation
 * takes from milliseconds to seconds. */
static const double PROGRESS_EVERY_S = 10.0;

static void fit_usage(FILE *out)
{
    fprintf(out,
        "usage: %s fit [options] --fit SPEC --part PART --measured CSV [--part ...] [--predict PART]\n"
        "\n"
        "Finds the scene values that best explain measured drops of one or more parts\n"
        "(one feeder: the values are shared), by maximum likelihood of all the counts\n"
        "together, the pose probabilities from simulated drops at each trial value\n"
        "(the same drops every time: common random numbers); then weighs the values\n"
        "around the best by their likelihood, for 95%% intervals of the parameters and\n"
        "predictions averaged over what the data allow (docs/calibration.md).\n"
        "\n"
        "Prints one CSV row per part and pose class:\n"
        "  part,role,pose,count,p_measured,p_best,p,ci_lo,ci_hi\n"
        "role: fitted (the part had measurements) or predicted (--predict); count,\n"
        "p_measured: the measurements (empty for predicted parts); p_best: the\n"
        "simulated probability at the best fit (smoothed: each class given alpha = 1/2\n"
        "more drops, so that a pose seen but never simulated is not impossible); p:\n"
        "averaged over the likelihood-weighted values, ci_lo, ci_hi: its 95%% interval,\n"
        "which carries both the parameters' spread and the simulation's own error\n"
        "(a predicted part's also the fitted parts' scatter about the model).\n"
        "stderr: before the first evaluation, the most the fit can cost (evaluations,\n"
        "drops); after it, an estimate in seconds; then a progress line every 10 s\n"
        "(evaluation, stage and round, best log-likelihood so far, time left at most);\n"
        "at the end the fitted values with their intervals (and whether the data\n"
        "identify them), the initial modes' scores, the goodness of fit per part from\n"
        "fresh drops (the fitted scene, at its best and at its weighted-mean values,\n"
        "simulated with a seed no evaluation used: Pearson's X^2 of the measured and\n"
        "simulated counts, p, and the total variation distance TV; the in-sample\n"
        "figures, from the drops that chose the best values, only as a diagnostic) and\n"
        "the cost (evaluations, drops, wall and CPU seconds).\n"
        "\n", prog);
    fprintf(out,
        "  --fit SPEC       the parameters to fit and their ranges, comma-separated:\n"
        "                   KEY=LO:HI with KEY one of height (m), belt_speed (m/s),\n"
        "                   mu, restitution, vibration (degrees), gravity (m/s^2),\n"
        "                   tumble (rad/s), contact_time (s, or multiples of each\n"
        "                   part's automatic duration as 0.3x:3x, one multiple\n"
        "                   shared by the parts; searched on a log scale); and 'initial'\n"
        "                   alone to fit the initial mode as a discrete choice\n"
        "                   (uniform, bootstrap, stationary): with two or more parts\n"
        "                   the mode whose fits to all parts but one best predict the\n"
        "                   one left out is kept (a search per mode and part, and one\n"
        "                   more); with one part, the best fit's, with a warning.\n"
        "                   e.g. --fit mu=0.1:0.8,restitution=0.05:0.7,initial\n"
        "  --part PART      a part file (OFF, STL, OBJ), followed by its --measured\n"
        "  --measured CSV   its measured counts: pose,count (or pose,p,n), the poses\n"
        "                   numbered as 'posedrop --group PART' numbers its classes\n"
        "                   (poses never seen may be left out)\n"
        "  --predict PART   a part without measurements, predicted at the fit\n"
        "  --no-group       measured poses are posedrop's poses, not classes\n"
        "  --units U        unit of every part file's coordinates: m (default), cm,\n"
        "                   mm, in\n"
        "  --scene FILE     the values not fitted ('key = value' lines, as for\n"
        "                   'posedrop --scene'; default the paper's scene)\n"
        "  -n N             simulated drops per part and evaluation, 10..10^7 (default\n"
        "                   1000; raised to 10 (K+1) for the stationary start of a\n"
        "                   part of K classes of symmetric poses); the search and the\n"
        "                   weighting's points run N/4\n"
        "  --seed S         the drops' seed (default 1): the same at every evaluation of\n"
        "                   the search, another derived from it for later stages\n"
        "  -j THREADS       threads (default: all cores); never changes results\n"
        "  --engine E       impulse (default), ode or bullet\n"
        "  --max-evals N    Nelder-Mead evaluations per search (default 150): the\n"
        "                   simplex stops once it has spent N, finishing its step (up\n"
        "                   to N + d + 1); each search's design of 4d+1 points and\n"
        "                   its 2 best points on N drops, the\n"
        "                   weighting (1 + 3 to 6 rounds of --points), the predicted\n"
        "                   parts' --points and the 2 fresh-drop checks come on top,\n"
        "                   and 'initial' runs 3 searches (3 (parts + 1) with two or\n"
        "                   more parts)\n"
        "  --points M       likelihood-weighted values per round, 3 to 6 rounds\n"
        "                   (default 8 (d+1) for d parameters)\n"
        "  --out FILE       the fitted scene, a file --scene reads\n"
        "  --params FILE    CSV parameter,value,lo,hi,mean,range_lo,range_hi,unit: the\n"
        "                   best value, the 95%% interval and the weighted mean (unit\n"
        "                   auto: multiples of each part's automatic contact time)\n"
        "  --gof FILE       CSV part,n,classes,loglik,chi2,df,p,tv (in-sample), then\n"
        "                   fresh_chi2,fresh_df,fresh_p,fresh_tv (fresh drops at the best\n"
        "                   values) and fresh_mean_* (at the weighted means)\n"
        "  --help           this help\n");
}

static int fit_fail(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "%s: fit: ", prog);
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n%s: see '%s fit --help'\n", prog, prog);
    return EXIT_USAGE;
}

/* The index of text among names, -1 if none. */
static int choice(const char *text, const char *const *names, int n)
{
    for (int i = 0; i < n; i++)
        if (strcmp(text, names[i]) == 0)
            return i;
    return -1;
}

static int number(const char *s, size_t n, double *out)
{
    return n > 0 && pd_parse_double(s, n, out) == PD_NUM_OK;
}

/* --fit: KEY=LO:HI items and 'initial'. The keys point into spec (modified). */
static int parse_spec(char *spec, pd_fit_param *params, int *nparams, int *fit_initial)
{
    for (char *item = strtok(spec, ","); item; item = strtok(NULL, ",")) {
        if (strcmp(item, "initial") == 0) {
            *fit_initial = 1;
            continue;
        }
        char *eq = strchr(item, '='), *colon = eq ? strchr(eq, ':') : NULL;
        if (!eq || !colon)
            return fit_fail("--fit: expected KEY=LO:HI or initial, got '%s'%s", item, "");
        if (*nparams == PD_FIT_MAX_PARAMS)
            return fit_fail("--fit: at most %s parameters at once%s", "7", "");
        *eq = '\0';
        pd_fit_param *p = &params[(*nparams)++];
        p->key = item;
        p->log = strcmp(item, "contact_time") == 0;
        /* contact_time=0.3x:3x: multiples of each part's automatic duration. */
        size_t nlo = (size_t)(colon - eq - 1), nhi = strlen(colon + 1);
        int xlo = nlo > 1 && colon[-1] == 'x', xhi = nhi > 1 && colon[nhi] == 'x';
        if ((xlo || xhi) && !(p->log && xlo && xhi))
            return fit_fail("--fit: %s: %s", item,
                            p->log ? "a range in multiples of auto has both ends so, as 0.3x:3x"
                                   : "only contact_time takes multiples of auto (0.3x:3x)");
        p->multiple = xlo;
        if (!number(eq + 1, nlo - (size_t)xlo, &p->lo) ||
            !number(colon + 1, nhi - (size_t)xhi, &p->hi))
            return fit_fail("--fit: %s: expected a range LO:HI of two numbers, got '%s'", item,
                            eq + 1);
    }
    return -1;
}

/* The measured file of a part, as counts per class (k of them; poses with
 * --no-group), or with sets of poses ("3|4") as counts per cell: every class
 * not in a set its own cell, in class order, then the sets (*cell_of: k
 * cells, *ncells). */
static int read_counts(const char *path, const char *part, int k, int group, long **count,
                       int **cell_of, int *ncells)
{
    viz_measured *m = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    pd_status st = viz_measured_read_sets(path, &m, &diag);
    if (st != PD_OK) {
        fprintf(stderr, "%s: %s\n", prog, diag.message);
        return 0;
    }
    int ok = 1, maxpose = m->npose;
    if (m->n <= 0) {
        fprintf(stderr, "%s: %s: the fit needs counts: columns pose,count, or pose,p,n\n", prog,
                path);
        ok = 0;
    } else if (maxpose > k) {
        if (group)
            fprintf(stderr, "%s: %s: pose class %d, but %s has %d pose class%s (numbered as "
                    "'posedrop --group' numbers them; --no-group for its poses)\n", prog, path,
                    maxpose, part, k, k == 1 ? "" : "es");
        else
            fprintf(stderr, "%s: %s: pose %d, but %s has %d pose%s\n", prog, path, maxpose,
                    part, k, k == 1 ? "" : "s");
        ok = 0;
    }
    if (ok && !(*count = calloc((size_t)k, sizeof **count))) {
        fprintf(stderr, "%s: out of memory\n", prog);
        ok = 0;
    }
    if (ok && m->nsets && !(*cell_of = malloc(sizeof **cell_of * (size_t)k))) {
        fprintf(stderr, "%s: out of memory\n", prog);
        ok = 0;
    }
    if (ok && m->nsets) {
        /* The sets' cells after the classes counted alone. */
        for (int c = 0; c < k; c++)
            (*cell_of)[c] = -1;
        for (int s = 0, at = 0; s < m->nsets; at += m->set_size[s], s++)
            for (int a = 0; a < m->set_size[s]; a++)
                (*cell_of)[m->set_pose[at + a] - 1] = -2 - s;
        int n = 0;
        for (int c = 0; c < k; c++)
            if ((*cell_of)[c] == -1) {
                (*count)[n] = c < m->npose ? lround(m->p[c] * (double)m->n) : 0;
                (*cell_of)[c] = n++;
            }
        for (int s = 0; s < m->nsets; s++)
            (*count)[n + s] = lround(m->set_p[s] * (double)m->n);
        for (int c = 0; c < k; c++)
            if ((*cell_of)[c] <= -2)
                (*cell_of)[c] = n - 2 - (*cell_of)[c];
        *ncells = n + m->nsets;
    }
    for (int i = 0; ok && !m->nsets && i < m->npose; i++)
        (*count)[i] = lround(m->p[i] * (double)m->n);
    viz_measured_free(m);
    return ok;
}

typedef struct {
    const char *path, *measured;
    pd_mesh *mesh;
    pd_part *part;
    pd_static_result *res;
    int *class_of, nclasses;
    long *count;
    int *cell_of, ncells; /* with sets of poses measured; else NULL */
} fit_input;

static int load_part(fit_input *in, const pd_mesh_read_options *read, int group)
{
    pd_diag diag;
    pd_diag_init(&diag);
    pd_part_options po;
    pd_part_options_default(&po);
    pd_status st = pd_mesh_read(in->path, read, &in->mesh, &diag);
    if (st == PD_OK)
        st = pd_part_build(in->mesh, &po, &in->part, &diag);
    if (st == PD_OK) {
        /* The same warning as the command's, before minutes of fitting. */
        plausible_warn_size(in->path, in->part->size, read->units);
        st = pd_static_estimate(in->part, NULL, &in->res, &diag);
    }
    if (st == PD_OK && group) {
        in->class_of = malloc(sizeof *in->class_of * (size_t)in->res->nposes);
        st = in->class_of ? pd_pose_classes(in->part, in->res, in->class_of, &in->nclasses, &diag)
                          : PD_ERR_NOMEM;
    } else if (st == PD_OK) {
        in->nclasses = in->res->nposes;
    }
    if (st != PD_OK) {
        cli_say_failure(in->path, st, &diag);
        return 0;
    }
    return !in->measured || read_counts(in->measured, in->path, in->nclasses, group,
                                        &in->count, &in->cell_of, &in->ncells);
}

static const char *initial_name(pd_initial i)
{
    return i == PD_INITIAL_BOOTSTRAP ? "bootstrap" : i == PD_INITIAL_STATIONARY ? "stationary"
                                                                              : "uniform";
}

/* A scene file that pd_scene_read reads back to the same scene. */
static void write_scene(FILE *f, const pd_fit_result *r, const pd_fit_param *params,
                        const fit_input *in, int nin)
{
    const pd_scene *s = &r->scene;
    fprintf(f, "# posedrop fit: the scene that best explains the measured drops of");
    for (int i = 0; i < nin; i++)
        if (in[i].count)
            fprintf(f, " %s", in[i].path);
    fprintf(f, "\n# 95%% intervals:");
    for (int i = 0; i < r->nparams; i++) {
        const char *x = params[i].multiple ? "x" : "";
        fprintf(f, " %s %.6g%s [%.6g%s, %.6g%s]%s", params[i].key, r->value[i], x, r->lo[i], x,
                r->hi[i], x, i + 1 < r->nparams ? ";" : "");
    }
    fprintf(f, "\n");
    /* Every parameter as pd_scene_set reads it: a range of the base scene
     * stays a range. */
    char buf[128];
    for (int k = 0; k < PD_NPARAMS; k++)
        fprintf(f, "%s = %s\n", pd_scene_param_name((pd_scene_param)k),
                pd_scene_format(s, (pd_scene_param)k, buf, sizeof buf));
    fprintf(f, "restitution_law = %s\ninitial = %s\ngravity = %s\n",
            s->law == PD_RESTITUTION_ENERGETIC ? "energetic" : "poisson", initial_name(s->initial),
            pd_num_format(buf, sizeof buf, s->gravity, 1.0));
}

/* The unit of a parameter's values as --fit gave them ("auto": multiples of
 * each part's automatic contact time). */
static const char *param_unit(const pd_fit_param *q)
{
    static const char *const keys[] = {"height", "belt_speed", "vibration", "gravity",
                                       "contact_time", "tumble"};
    static const char *const units[] = {"m", "m/s", "deg", "m/s^2", "s", "rad/s"};
    if (q->multiple)
        return "auto";
    int i = choice(q->key, keys, 6);
    return i < 0 ? "" : units[i];
}

static void write_params(FILE *f, const pd_fit_result *r, const pd_fit_param *params)
{
    fprintf(f, "parameter,value,lo,hi,mean,range_lo,range_hi,unit\n");
    for (int i = 0; i < r->nparams; i++)
        fprintf(f, "%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%s\n", params[i].key, r->value[i],
                r->lo[i], r->hi[i], r->mean[i], params[i].lo, params[i].hi, param_unit(&params[i]));
}

static void write_gof(FILE *f, const pd_fit_result *r, const fit_input *in, int nin)
{
    fprintf(f, "part,n,classes,loglik,chi2,df,p,tv,fresh_chi2,fresh_df,fresh_p,fresh_tv,"
               "fresh_mean_chi2,fresh_mean_df,fresh_mean_p,fresh_mean_tv\n");
    for (int i = 0; i < nin; i++) {
        const pd_fit_part_result *q = &r->parts[i];
        const pd_fit_quality *b = &q->fresh_best, *m = &q->fresh_mean;
        if (in[i].count)
            fprintf(f, "%s,%ld,%d,%.10g,%.10g,%d,%.10g,%.10g,%.10g,%d,%.10g,%.10g,%.10g,%d,%.10g,"
                    "%.10g\n", in[i].path, q->n, q->nclasses, q->loglik, q->chi2, q->df,
                    q->pvalue, q->tv, b->chi2, b->df, b->pvalue, b->tv, m->chi2, m->df, m->pvalue,
                    m->tv);
    }
}

static void print_table(const pd_fit_result *r, const fit_input *in, int nin)
{
    printf("part,role,pose,count,p_measured,p_best,p,ci_lo,ci_hi,set\n");
    for (int i = 0; i < nin; i++) {
        const pd_fit_part_result *q = &r->parts[i];
        const int *of = in[i].cell_of;
        for (int c = 0; c < q->nclasses; c++) {
            printf("%s,%s,%d,", in[i].path, in[i].count ? "fitted" : "predicted", c + 1);
            /* A set holds two poses or more. */
            int cell = of ? of[c] : c, members = 0;
            for (int e = 0; of && e < q->nclasses; e++)
                members += of[e] == cell;
            int in_set = members >= 2;
            if (in[i].count && !in_set)
                printf("%ld,%.10g,", in[i].count[cell], (double)in[i].count[cell] / (double)q->n);
            else
                printf(",,");
            printf("%.10g,%.10g,%.10g,%.10g,", q->p_best[c], q->p[c], q->lo[c], q->hi[c]);
            /* A set's count is its own row's in the measured file: the
             * members name the set. */
            for (int e = 0, first = 1; in_set && e < q->nclasses; e++)
                if (of[e] == cell) {
                    printf("%s%d", first ? "" : "|", e + 1);
                    first = 0;
                }
            printf("\n");
        }
    }
}

/* How the fit did against fresh drops, as words. */
static void print_quality(const char *what, const pd_fit_quality *q)
{
    if (q->df <= 0)
        fprintf(stderr, "%s: fit: %s: X^2 = %.2f, TV %.3f: the data cannot test this fit (as many "
                "fitted parameters as free classes, or more)\n", prog, what, q->chi2, q->tv);
    else
        fprintf(stderr, "%s: fit: %s: X^2 = %.2f, df %d, p = %.3g, TV %.3f%s\n", prog, what,
                q->chi2, q->df, q->pvalue, q->tv,
                q->pvalue < 0.05 ? " (the model does not fit)" : "");
}

static void print_summary(const pd_fit_result *r, const pd_fit_param *params, const fit_input *in,
                          int nin, int fit_initial, double wall, double cpu)
{
    for (int i = 0; i < r->nparams; i++) {
        const pd_fit_param *q = &params[i];
        const char *x = q->multiple ? "x" : "";
        double span = q->log ? log(r->hi[i] / r->lo[i]) / log(q->hi / q->lo)
                             : (r->hi[i] - r->lo[i]) / (q->hi - q->lo);
        fprintf(stderr, "%s: fit: %s = %.4g%s, 95%% interval [%.4g%s, %.4g%s] (weighted mean "
                "%.4g%s; range %g%s:%g%s)%s\n", prog, q->key, r->value[i], x, r->lo[i], x,
                r->hi[i], x, r->mean[i], x, q->lo, x, q->hi, x,
                q->multiple ? " in multiples of each part's automatic duration" : "");
        if (span > UNIDENTIFIED_SHARE)
            fprintf(stderr, "%s: fit: %s is not identified by the data: its interval spans %.0f%% "
                    "of its range\n", prog, q->key, 100.0 * span);
    }
    if (fit_initial && r->initial_untested)
        fprintf(stderr, "%s: fit: initial %s: maximised log-likelihood uniform %.2f, bootstrap "
                "%.2f, stationary %.2f\n%s: fit: warning: with one part the initial mode is "
                "chosen on the counts it is fitted to, which cannot test it\n", prog,
                initial_name(r->initial), r->loglik_initial[PD_INITIAL_UNIFORM],
                r->loglik_initial[PD_INITIAL_BOOTSTRAP], r->loglik_initial[PD_INITIAL_STATIONARY],
                prog);
    else if (fit_initial)
        fprintf(stderr, "%s: fit: initial %s: log-likelihood of each part predicted by a fit to "
                "the others, summed: uniform %.2f, bootstrap %.2f, stationary %.2f\n", prog,
                initial_name(r->initial), r->loglik_initial[PD_INITIAL_UNIFORM],
                r->loglik_initial[PD_INITIAL_BOOTSTRAP], r->loglik_initial[PD_INITIAL_STATIONARY]);
    char what[4200];
    for (int i = 0; i < nin; i++) {
        const pd_fit_part_result *q = &r->parts[i];
        if (!in[i].count)
            continue;
        fprintf(stderr, "%s: fit: %s: %ld measured drops, %d classes\n", prog, in[i].path, q->n,
                q->nclasses);
        snprintf(what, sizeof what, "%s: fresh drops at the best values", in[i].path);
        print_quality(what, &q->fresh_best);
        snprintf(what, sizeof what, "%s: fresh drops at the weighted means", in[i].path);
        print_quality(what, &q->fresh_mean);
        fprintf(stderr, "%s: fit: %s: in-sample (the drops that chose the best values among "
                "the search's last few, a diagnostic): X^2 = %.2f, TV %.3f\n", prog, in[i].path,
                q->chi2, q->tv);
    }
    print_quality("all parts: fresh drops at the best values", &r->fresh_best);
    print_quality("all parts: fresh drops at the weighted means", &r->fresh_mean);
    fprintf(stderr, "%s: fit: all parts in-sample (a diagnostic): X^2 = %.2f, log-likelihood "
            "%.2f\n", prog, r->chi2, r->loglik);
    if (r->failed)
        fprintf(stderr, "%s: fit: warning: %ld of the %ld simulated drops failed (a solver could "
                "not go on) and are in no count\n", prog, r->failed, r->drops);
    if (r->dispersion > 1.0)
        fprintf(stderr, "%s: fit: X^2 is %.3g times what the noise explains: the intervals are "
                "widened for the model's misfit\n", prog, r->dispersion);
    int predicted = 0;
    for (int i = 0; i < r->nparts; i++)
        predicted += r->parts[i].n == 0;
    if (r->discrepancy > 0 && predicted)
        fprintf(stderr, "%s: fit: the fitted parts' probabilities scatter about the model's by "
                "%.3g sqrt(p (1 - p)) beyond their noise: the predicted parts' intervals carry "
                "that scatter; a prediction is no better than the model's fit to the parts it "
                "was fitted to\n", prog, sqrt(r->discrepancy));
    fprintf(stderr, "%s: fit: %d evaluations, %ld drops simulated, %d weighted values (effective "
            "%.1f); %.1f s wall, %.1f s CPU\n", prog, r->evaluations, r->drops, r->npoints,
            r->ess, wall, cpu);
    if (r->weigh_misfit_sd >= 0)
        fprintf(stderr, "%s: fit: the weighting's log-likelihood varies by %.3g (standard "
                "deviation) from one set of drops to another at the best values; its points "
                "were smoothed toward a quadratic about which they scatter by %.3g beyond that "
                "noise\n", prog, r->weigh_noise_sd, r->weigh_misfit_sd);
    if (r->ess < FEW_EFFECTIVE)
        fprintf(stderr, "%s: fit: warning: the weighting rests on %.1f effective values: the "
                "intervals and the averaged predictions are coarse (raise --points)\n", prog,
                r->ess);
}

/* Progress on stderr: the plan before the first evaluation, an estimate of
 * the time after it, then a line every PROGRESS_EVERY_S. */
typedef struct {
    double t0, c0, last;
} fit_clock;

static void fit_progress(const pd_fit_progress *g, void *user)
{
    fit_clock *k = user;
    double t = cli_wall_seconds() - k->t0;
    if (g->evaluation == 0) {
        fprintf(stderr, "%s: fit: at most %d evaluations and %ld drops\n", prog,
                g->max_evaluations, g->max_drops);
        return;
    }
    double cpu = cli_cpu_seconds() - k->c0;
    /* By drops, not evaluations: the search's evaluations run fewer drops
     * than the later ones. */
    double per_drop = g->drops > 0 ? cpu / (double)g->drops : 0.0;
    double left = (double)(g->max_drops - g->drops) * per_drop;
    if (g->evaluation == 1) {
        fprintf(stderr, "%s: fit: the first evaluation took %.2f s of CPU: at most about %.0f s "
                "of CPU in all\n", prog, cpu, per_drop * (double)g->max_drops);
        k->last = t;
        return;
    }
    if (t - k->last < PROGRESS_EVERY_S)
        return;
    k->last = t;
    char held[48] = "", round[32] = "", best[64] = "";
    if (g->held_out)
        snprintf(held, sizeof held, ", part %d left out", g->held_out);
    if (g->round)
        snprintf(round, sizeof round, " round %d", g->round);
    if (isfinite(g->best_loglik))
        snprintf(best, sizeof best, ", best log-likelihood %.2f", g->best_loglik);
    fprintf(stderr, "%s: fit: evaluation %d of at most %d (initial %s%s, %s%s%s); %.0f s of CPU "
            "so far, at most about %.0f s left\n", prog, g->evaluation, g->max_evaluations,
            g->initial, held, g->stage, round, best, cpu, left);
}

int cli_fit(int argc, char **argv)
{
    enum { F_FIT = 256, F_PART, F_MEASURED, F_PREDICT, F_NOGROUP, F_UNITS, F_SCENE, F_SEED,
           F_ENGINE, F_MAXEVALS, F_POINTS, F_OUT, F_PARAMS, F_GOF, F_HELP };
    static const struct option longopts[] = {
        {"fit", required_argument, 0, F_FIT},
        {"part", required_argument, 0, F_PART},
        {"measured", required_argument, 0, F_MEASURED},
        {"predict", required_argument, 0, F_PREDICT},
        {"no-group", no_argument, 0, F_NOGROUP},
        {"units", required_argument, 0, F_UNITS},
        {"scene", required_argument, 0, F_SCENE},
        {"seed", required_argument, 0, F_SEED},
        {"engine", required_argument, 0, F_ENGINE},
        {"max-evals", required_argument, 0, F_MAXEVALS},
        {"points", required_argument, 0, F_POINTS},
        {"out", required_argument, 0, F_OUT},
        {"params", required_argument, 0, F_PARAMS},
        {"gof", required_argument, 0, F_GOF},
        {"help", no_argument, 0, F_HELP},
        {0, 0, 0, 0},
    };
    if (!cli_writer())
        return 0; /* posedrop-mpi: one process fits */
    static fit_input in[MAX_PARTS];
    memset(in, 0, sizeof in);
    int nin = 0, group = 1, nparams = 0, fit_initial = 0;
    pd_fit_param params[PD_FIT_MAX_PARAMS];
    char *spec = NULL;
    const char *out_path = NULL, *params_path = NULL, *gof_path = NULL, *scene_path = NULL;
    pd_mesh_read_options read;
    pd_mesh_read_options_default(&read);
    pd_fit_options fo;
    pd_fit_options_default(&fo);
    pd_diag diag;
    pd_diag_init(&diag);
    opterr = 0;
    optind = 1;
    int c, code = -1;
    static const char *const units[] = {"m", "cm", "mm", "in"};
    static const char *const engines[] = {"impulse", "ode", "bullet"};
    while (code < 0 && (c = getopt_long(argc, argv, ":n:j:", longopts, NULL)) != -1) {
        long long v = 0;
        switch (c) {
        case F_FIT:
            if (spec)
                code = fit_fail("--fit given twice: list the parameters in one%s%s", "", "");
            else if (!(spec = strdup(optarg)))
                code = EXIT_INTERNAL;
            else
                code = parse_spec(spec, params, &nparams, &fit_initial);
            break;
        case F_PART:
        case F_PREDICT:
            if (nin == MAX_PARTS)
                code = fit_fail("at most %s parts%s", "64", "");
            else
                in[nin++].path = optarg;
            if (code < 0 && c == F_PART)
                in[nin - 1].measured = ""; /* a --measured must follow */
            break;
        case F_MEASURED:
            if (nin == 0 || !in[nin - 1].measured || in[nin - 1].measured[0])
                code = fit_fail("--measured %s: expected after its --part%s", optarg, "");
            else
                in[nin - 1].measured = optarg;
            break;
        case F_NOGROUP: group = 0; break;
        case F_UNITS:
            if ((v = choice(optarg, units, 4)) < 0)
                code = fit_fail("--units: expected m, cm, mm or in, got '%s'%s", optarg, "");
            else
                read.units = (pd_units)v;
            break;
        case F_ENGINE:
            if ((v = choice(optarg, engines, 3)) < 0)
                code = fit_fail("--engine: expected impulse, ode or bullet, got '%s'%s", optarg, "");
            else
                fo.engine = (pd_engine_kind)v;
            break;
        case F_SCENE: scene_path = optarg; break;
        case F_OUT: out_path = optarg; break;
        case F_PARAMS: params_path = optarg; break;
        case F_GOF: gof_path = optarg; break;
        case F_HELP: fit_usage(stdout); code = 0; break;
        case 'n':
        case 'j':
        case F_SEED:
        case F_MAXEVALS:
        case F_POINTS: {
            pd_num_rule rule = {c == 'n' ? "a number of drops" : c == 'j' ? "a number of threads"
                                : c == F_SEED ? "a seed" : "a count",
                                1, 0, 0, 0, 0, c == 'n' ? 10 : c == F_SEED ? 0 : 1,
                                c == 'j' ? 256 : c == F_SEED ? LLONG_MAX : c == 'n' ? 10000000
                                                                                   : 100000};
            int outcome = pd_num_read(&rule, optarg, NULL, &v);
            if (outcome != PD_NUM_OK) {
                char msg[256];
                code = fit_fail("%s: %s", c == 'n' ? "-n" : c == 'j' ? "-j" : c == F_SEED
                                ? "--seed" : c == F_MAXEVALS ? "--max-evals" : "--points",
                                pd_num_message(msg, sizeof msg, &rule, optarg, outcome));
                break;
            }
            if (c == 'n')
                fo.ndrops = (long)v;
            else if (c == 'j')
                fo.threads = (int)v;
            else if (c == F_SEED)
                fo.seed = (uint64_t)v;
            else if (c == F_MAXEVALS)
                fo.max_evals = (int)v;
            else
                fo.npoints = (int)v;
            break;
        }
        case ':':
            code = fit_fail("option '%s' needs a value%s", argv[optind - 1], "");
            break;
        default:
            code = fit_fail("unknown option '%s'%s", argv[optind - 1], "");
            break;
        }
    }
    pd_scene scene;
    pd_scene_default(&scene);
    int nfitted = 0;
    for (int i = 0; i < nin; i++)
        nfitted += in[i].measured != NULL;
    if (code < 0 && optind < argc)
        code = fit_fail("unexpected argument '%s' (parts are given with --part or --predict)%s",
                        argv[optind], "");
    if (code < 0 && !spec)
        code = fit_fail("nothing to fit: give --fit KEY=LO:HI[,...]%s%s", "", "");
    if (code < 0 && nparams == 0)
        code = fit_fail("--fit: give at least one KEY=LO:HI (initial is fitted beside them)%s%s",
                        "", "");
    for (int i = 0; code < 0 && i < nin; i++)
        if (in[i].measured && !in[i].measured[0])
            code = fit_fail("--part %s: expected its --measured CSV after it%s", in[i].path, "");
    if (code < 0 && nfitted == 0)
        code = fit_fail("no part to fit: give --part PART --measured CSV%s%s", "", "");
    /* The command offers every engine: it links libposedrop-bullet. */
    if (code < 0 && pd_bullet_register() != PD_OK) {
        fprintf(stderr, "%s: the Bullet engine could not be registered\n", prog);
        code = EXIT_INTERNAL;
    }
    if (code < 0 && scene_path && pd_scene_read(scene_path, &scene, &diag) != PD_OK) {
        fprintf(stderr, "%s: %s\n", prog, diag.message);
        code = EXIT_USAGE;
    }
    out_file outs[3] = {{0}};
    const char *paths[3] = {out_path, params_path, gof_path};
    /* No output may land on an input or on another output. */
    static cli_file files[2 * MAX_PARTS + 4];
    int nfiles = 0;
    static const char *const out_names[3] = {"out", "params", "gof"};
    for (int i = 0; i < nin; i++) {
        files[nfiles++] = (cli_file){in[i].measured ? "part" : "predict", in[i].path, 0, 1};
        if (in[i].measured)
            files[nfiles++] = (cli_file){"measured", in[i].measured, 0, 1};
    }
    if (scene_path)
        files[nfiles++] = (cli_file){"scene", scene_path, 0, 1};
    for (int k = 0; k < 3; k++)
        if (paths[k])
            files[nfiles++] = (cli_file){out_names[k], paths[k], 1, 1};
    if (code < 0 && !cli_files_apart(files, nfiles))
        code = EXIT_USAGE;
    for (int k = 0; code < 0 && k < 3; k++)
        if (paths[k] && !out_open(&outs[k], paths[k]))
            code = EXIT_USAGE;
    for (int i = 0; code < 0 && i < nin; i++)
        if (!load_part(&in[i], &read, group))
            code = EXIT_USAGE;
    /* A signal before the fit ends the run here, nothing written. */
    if (code < 0 && signals_caught())
        code = cli_interrupt_code();
    pd_fit_result *r = NULL;
    if (code < 0) {
        pd_fit_part parts[MAX_PARTS];
        for (int i = 0; i < nin; i++)
            parts[i] = (pd_fit_part){in[i].part,  in[i].res,     in[i].class_of, in[i].nclasses,
                                     in[i].count, in[i].cell_of, in[i].ncells};
        fo.fit_initial = fit_initial;
        signals_catch_fit(&fo);
        double t0 = cli_wall_seconds(), c0 = cli_cpu_seconds();
        fit_clock clock = {t0, c0, 0.0};
        fo.progress = fit_progress;
        fo.progress_user = &clock;
        pd_status st = pd_fit_run(parts, nin, params, nparams, &scene, &fo, &r, &diag);
        if (st == PD_ERR_CANCELLED) {
            fprintf(stderr, "%s: fit: interrupted: nothing written (a fit stopped part way has no "
                    "result; earlier files are as they were)\n", prog);
            code = cli_interrupt_code();
        } else if (st != PD_OK) {
            fprintf(stderr, "%s: fit: %s\n", prog, diag.message[0] ? diag.message
                                                                    : pd_status_str(st));
            code = pd_status_is_input_error(st) || st == PD_ERR_USAGE ? EXIT_USAGE
                                                                      : EXIT_INTERNAL;
        } else {
            double wall = cli_wall_seconds() - t0, cpu = cli_cpu_seconds() - c0;
            if (outs[0].f)
                write_scene(outs[0].f, r, params, in, nin);
            if (outs[1].f)
                write_params(outs[1].f, r, params);
            if (outs[2].f)
                write_gof(outs[2].f, r, in, nin);
            /* The files are put in place together, once stdout is written
             * too: a failed run leaves every earlier file as it was. */
            code = 0;
            for (int k = 0; k < 3; k++)
                if (!out_close(&outs[k]))
                    code = EXIT_INTERNAL;
            if (code == 0) {
                print_summary(r, params, in, nin, fit_initial, wall, cpu);
                print_table(r, in, nin);
                if (fflush(stdout) != 0 || ferror(stdout)) {
                    fprintf(stderr, "%s: fit: error writing the output: %s\n", prog,
                            strerror(errno));
                    code = EXIT_INTERNAL;
                }
            }
            out_file *const placed[3] = {&outs[0], &outs[1], &outs[2]};
            if (code == 0 && !out_place_all(placed, 3))
                code = EXIT_INTERNAL;
        }
    }
    for (int k = 0; k < 3; k++)
        out_abort(&outs[k]);
    pd_fit_result_free(r);
    for (int i = 0; i < nin; i++) {
        free(in[i].count);
        free(in[i].cell_of);
        free(in[i].class_of);
        pd_static_result_free(in[i].res);
        pd_part_free(in[i].part);
        pd_mesh_free(in[i].mesh);
    }
    free(spec);
    return code < 0 ? 0 : code;
}
