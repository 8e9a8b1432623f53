/* sensitivity.c: first-order variance-based indices of the pose indicators
 * from the drops' own draws (posedrop/sensitivity.h; docs/uncertainty.md).
 *
 * Given data, no extra drops: every drop of a run with ranges already holds
 * a value of each parameter and an outcome, so E[Y | X_i] is estimated by
 * the mean of Y over bins of drops ordered by X_i (Plischke, Borgonovo and
 * Smith 2013, given-data estimation), with the between-bin sum of squares
 * corrected for what noise alone puts there (the one-way analysis of
 * variance's expected mean squares), and the interval by resampling the
 * drops (Efron's percentile bootstrap). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/rng.h"
#include "base/stats.h"
#include "posedrop/sensitivity.h"
#include "posedrop/tolerances.h"
#include "sim/markov.h"

/* Bins: ceil(sqrt(n)) balances the two errors of a binned conditional
 * mean, its noise (n / M drops per bin) and its coarseness (a bin averages
 * E[Y | X] over 1 / M of the range); at most 100, which resolves a
 * threshold in X to 1% of the range. */
enum { MAX_BINS = 100 };

static int bin_count(long n)
{
    int m = (int)ceil(sqrt((double)n));
    return m < 2 ? 2 : m > MAX_BINS ? MAX_BINS : m;
}

/* The corrected index from bin sums: nb[b] the weights, n2[b] the squared
 * weights and sb[b * stride] the weighted sums of y of bin b (m bins); sy,
 * syy the totals of y and y^2, n the total weight and w2 the total squared
 * weight. Noise alone puts sigma^2 (C - w2 / n) into the between-bin sum of
 * squares SSB and sigma^2 (n - C) into the within-bin one, C = sum_b n2[b] /
 * nb[b]; unweighted, C = m: the analysis of variance's m - 1 and n - m. The
 * weights are a resample's counts, whose repeated drops would otherwise
 * count as independent ones. S is then (SSB - noise) / n over the variance
 * of y, SST / (n - w2 / n). NAN when y does not vary. */
static double index_of(double n, int m, const double *nb, const double *n2, const double *sb,
                       size_t stride, double sy, double syy, double w2)
{
    double sst = syy - sy * sy / n;
    if (!(sst > 0.0))
        return NAN;
    double ssb = -sy * sy / n, c = 0.0;
    for (int b = 0; b < m; b++)
        if (nb[b] > 0.0) {
            ssb += sb[(size_t)b * stride] * sb[(size_t)b * stride] / nb[b];
            c += n2[b] / nb[b];
        }
    double sigma2 = (sst - ssb) / (n - c);
    double noise = sigma2 * (c - w2 / n);
    return (ssb - noise) / n / (sst / (n - w2 / n));
}

/* Sums over the drops in order (ranked by x), weighted by w (NULL: 1 each),
 * into m bins of equal weight: a drop goes to the bin its cumulative weight
 * starts in. With cat, drop j adds w to sb[bin * k + cat[j]]; else w y[j]
 * to sb[bin]. Returns the total squared weight. */
static double bin_sums(const long *order, long n, const unsigned *w, int m, const int *cat,
                       const double *y, int k, double *nb, double *n2, double *sb)
{
    memset(nb, 0, sizeof *nb * (size_t)m);
    memset(n2, 0, sizeof *n2 * (size_t)m);
    memset(sb, 0, sizeof *sb * (size_t)m * (size_t)k);
    long pos = 0;
    double w2 = 0.0;
    for (long r = 0; r < n; r++) {
        long j = order[r];
        double wj = w ? w[j] : 1.0;
        if (wj == 0.0)
            continue;
        int b = (int)((double)pos * m / (double)n);
        b = b >= m ? m - 1 : b;
        pos += (long)wj;
        nb[b] += wj;
        n2[b] += wj * wj;
        w2 += wj * wj;
        if (cat)
            sb[(size_t)b * (size_t)k + (size_t)cat[j]] += wj;
        else
            sb[b] += wj * y[j];
    }
    return w2;
}

/* One bootstrap resample: w[j] how often drop j is drawn in n draws. */
static void resample(uint64_t seed, int which, long n, unsigned *w)
{
    pd_rng r;
    pd_rng_init(&r, seed, (uint64_t)which);
    memset(w, 0, sizeof *w * (size_t)n);
    for (long i = 0; i < n; i++) {
        long j = (long)(pd_rng_uniform(&r) * (double)n);
        w[j < n ? j : n - 1]++;
    }
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The 95% percentile interval of v[0..nv) (sorted in place), unclipped. */
static void percentile_raw(double *v, int nv, double *lo, double *hi)
{
    qsort(v, (size_t)nv, sizeof *v, by_value);
    double at[2] = {0.025 * (nv - 1), 0.975 * (nv - 1)}, out[2];
    for (int s = 0; s < 2; s++) {
        int i = (int)at[s];
        double f = at[s] - i;
        out[s] = i + 1 < nv ? v[i] + f * (v[i + 1] - v[i]) : v[i];
    }
    *lo = out[0];
    *hi = out[1];
}

/* The same, clipped to [0, 1]. */
static void percentile_interval(double *v, int nv, double *lo, double *hi)
{
    percentile_raw(v, nv, lo, hi);
    *lo = fmin(fmax(*lo, 0.0), 1.0);
    *hi = fmin(fmax(*hi, 0.0), 1.0);
}

static double clip01(double s)
{
    return isnan(s) ? 0.0 : fmin(fmax(s, 0.0), 1.0);
}

/* Ranks: order[r] the drop of rank r by key (ties by index, so the order is
 * one for given data). */
typedef struct {
    double key;
    long j;
} ranked;

static int by_key(const void *a, const void *b)
{
    const ranked *p = a, *q = b;
    if (p->key != q->key)
        return (p->key > q->key) - (p->key < q->key);
    return (p->j > q->j) - (p->j < q->j);
}

static pd_status rank_order(const double *key, long n, long *order, pd_diag *diag)
{
    ranked *t = malloc(sizeof *t * (size_t)n);
    if (!t)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for %ld ranks", n);
    for (long j = 0; j < n; j++)
        t[j] = (ranked){key[j], j};
    qsort(t, (size_t)n, sizeof *t, by_key);
    for (long r = 0; r < n; r++)
        order[r] = t[r].j;
    free(t);
    return PD_OK;
}

pd_status pd_first_order_index(const double *x, const double *y, long n, uint64_t seed,
                               double *index, double *lo, double *hi, pd_diag *diag)
{
    if (!x || !y || !index || !lo || !hi)
        return pd_fail(diag, PD_ERR_USAGE, "pd_first_order_index: NULL argument");
    if (n < 4)
        return pd_fail(diag, PD_ERR_USAGE, "pd_first_order_index: %ld pairs: at least 4 are "
                       "needed", n);
    for (long j = 0; j < n; j++)
        if (!isfinite(x[j]) || !isfinite(y[j]))
            return pd_fail(diag, PD_ERR_NONFINITE, "pd_first_order_index: pair %ld is not "
                           "finite", j);
    int m = bin_count(n);
    long *order = malloc(sizeof *order * (size_t)n);
    unsigned *w = malloc(sizeof *w * (size_t)n);
    double *nb = malloc(sizeof *nb * MAX_BINS), *sb = malloc(sizeof *sb * MAX_BINS);
    double *n2 = malloc(sizeof *n2 * MAX_BINS);
    double *rep = malloc(sizeof *rep * PD_SENSITIVITY_RESAMPLES);
    pd_status st = order && w && nb && n2 && sb && rep ? rank_order(x, n, order, diag)
                                                 : pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    if (st == PD_OK) {
        double sy = 0.0, syy = 0.0;
        for (long j = 0; j < n; j++) {
            sy += y[j];
            syy += y[j] * y[j];
        }
        double w2 = bin_sums(order, n, NULL, m, NULL, y, 1, nb, n2, sb);
        double s = index_of((double)n, m, nb, n2, sb, 1, sy, syy, w2);
        *index = clip01(s);
        *lo = *hi = 0.0;
        for (int b = 0; !isnan(s) && b < PD_SENSITIVITY_RESAMPLES; b++) {
            resample(seed, b, n, w);
            double ry = 0.0, ryy = 0.0;
            for (long j = 0; j < n; j++) {
                ry += w[j] * y[j];
                ryy += w[j] * y[j] * y[j];
            }
            double rw2 = bin_sums(order, n, w, m, NULL, y, 1, nb, n2, sb);
            double r = index_of((double)n, m, nb, n2, sb, 1, ry, ryy, rw2);
            rep[b] = isnan(r) ? 0.0 : r;
        }
        if (!isnan(s))
            percentile_interval(rep, PD_SENSITIVITY_RESAMPLES, lo, hi);
    }
    free(order);
    free(w);
    free(nb);
    free(n2);
    free(sb);
    free(rep);
    return st;
}

void pd_sensitivity_free(pd_sensitivity *s)
{
    if (!s)
        return;
    free(s->rows);
    free(s);
}

/* The drops the sensitivity uses: settled, and of a stationary run those
 * started uniform (a drop started resting on a pose would add its start's
 * variation, which no parameter explains). cat[j] is the outcome (class
 * with class_of), q[j * PD_NPARAMS + i] the quantile of parameter i. */
static long used_drops(const pd_sim_result *r, const pd_scene *sc, double size,
                       const int *class_of, int *cat, double *q)
{
    long n = 0;
    for (long t = 0; t < r->n; t++) {
        const pd_trial *tr = &r->trials[t];
        long drop = r->nshards > 0 ? r->shard + t * r->nshards : t;
        if (tr->end != PD_END_SETTLED || tr->pose < 0)
            continue;
        if (r->transitions &&
            pd_stationary_start(drop, r->pose_drops,
                                r->chain_class_of ? r->chain_states : r->nposes) >= 0)
            continue;
        cat[n] = class_of ? class_of[tr->pose] : tr->pose;
        for (int i = 0; i < PD_NPARAMS; i++)
            q[(size_t)n * PD_NPARAMS + (size_t)i] =
                pd_scene_quantile(sc, (pd_scene_param)i, size, tr->param[i]);
        n++;
    }
    return n;
}

/* Which third of parameter i's distribution drop j's value fell in: 0
 * lower, 1 middle, 2 upper. */
static int third_of(const double *q, long j, int i)
{
    double u = q[(size_t)j * PD_NPARAMS + (size_t)i];
    return u < 1.0 / 3.0 ? 0 : u > 2.0 / 3.0 ? 2 : 1;
}

/* Thirds: the pose's share of the drops in the lower and upper third of
 * the parameter's distribution. */
static void thirds(const int *cat, const double *q, long n, int i, int k, pd_sensitivity_row *row)
{
    long lo_n = 0, hi_n = 0, lo_c = 0, hi_c = 0;
    for (long j = 0; j < n; j++) {
        double u = q[(size_t)j * PD_NPARAMS + (size_t)i];
        if (u < 1.0 / 3.0) {
            lo_n++;
            lo_c += cat[j] == k;
        } else if (u > 2.0 / 3.0) {
            hi_n++;
            hi_c += cat[j] == k;
        }
    }
    row->n_low = lo_n;
    row->n_high = hi_n;
    row->p_low = lo_n ? (double)lo_c / (double)lo_n : 0.0;
    row->p_high = hi_n ? (double)hi_c / (double)hi_n : 0.0;
    pd_wilson(lo_c, lo_n, PD_Z95, &row->p_low_lo, &row->p_low_hi);
    pd_wilson(hi_c, hi_n, PD_Z95, &row->p_high_lo, &row->p_high_hi);
}

/* Every pose's index for parameter i, point and interval, into rows[k *
 * nparams + col]: one pass over the ranked drops per resample serves all
 * poses. */
static pd_status indices(const int *cat, const double *q, long n, int i, int k, int col,
                         int nparams, uint64_t seed, pd_sensitivity_row *rows, pd_diag *diag)
{
    int m = bin_count(n);
    double *key = malloc(sizeof *key * (size_t)n);
    long *order = malloc(sizeof *order * (size_t)n);
    unsigned *w = malloc(sizeof *w * (size_t)n);
    double *nb = malloc(sizeof *nb * MAX_BINS), *n2 = malloc(sizeof *n2 * MAX_BINS);
    double *sb = malloc(sizeof *sb * MAX_BINS * (size_t)k);
    double *tot = malloc(sizeof *tot * (size_t)k);
    double *rep = malloc(sizeof *rep * PD_SENSITIVITY_RESAMPLES * (size_t)k);
    double *point = malloc(sizeof *point * (size_t)k);
    /* The effect's resamples: the pose's weighted counts in the lower and
     * upper thirds. */
    double *eff = malloc(sizeof *eff * PD_SENSITIVITY_RESAMPLES * (size_t)k);
    double *cnt = malloc(sizeof *cnt * 2 * (size_t)k);
    pd_status st = PD_OK;
    if (!key || !order || !w || !nb || !n2 || !sb || !tot || !rep || !point || !eff || !cnt)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the sensitivity");
    for (long j = 0; st == PD_OK && j < n; j++)
        key[j] = q[(size_t)j * PD_NPARAMS + (size_t)i];
    if (st == PD_OK)
        st = rank_order(key, n, order, diag);
    for (int b = -1; st == PD_OK && b < PD_SENSITIVITY_RESAMPLES; b++) {
        if (b >= 0)
            resample(seed ^ (uint64_t)(i + 1) * 0x9e3779b97f4a7c15ULL, b, n, w);
        if (b >= 0) {
            double nl = 0.0, nh = 0.0;
            memset(cnt, 0, sizeof *cnt * 2 * (size_t)k);
            for (long j = 0; j < n; j++) {
                int t = third_of(q, j, i);
                if (t == 0) {
                    nl += w[j];
                    cnt[cat[j]] += w[j];
                } else if (t == 2) {
                    nh += w[j];
                    cnt[k + cat[j]] += w[j];
                }
            }
            for (int c = 0; c < k; c++)
                eff[(size_t)c * PD_SENSITIVITY_RESAMPLES + (size_t)b] =
                    (nh > 0.0 ? cnt[k + c] / nh : 0.0) - (nl > 0.0 ? cnt[c] / nl : 0.0);
        }
        double w2 = bin_sums(order, n, b >= 0 ? w : NULL, m, cat, NULL, k, nb, n2, sb);
        memset(tot, 0, sizeof *tot * (size_t)k);
        for (int bin = 0; bin < m; bin++)
            for (int c = 0; c < k; c++)
                tot[c] += sb[(size_t)bin * (size_t)k + (size_t)c];
        for (int c = 0; c < k; c++) {
            /* An indicator: y^2 = y. */
            double s = index_of((double)n, m, nb, n2, sb + c, (size_t)k, tot[c], tot[c], w2);
            if (b < 0)
                point[c] = s;
            else
                rep[(size_t)c * PD_SENSITIVITY_RESAMPLES + (size_t)b] = isnan(s) ? 0.0 : s;
        }
    }
    for (int c = 0; st == PD_OK && c < k; c++) {
        pd_sensitivity_row *row = &rows[(size_t)c * (size_t)nparams + (size_t)col];
        row->index = clip01(point[c]);
        row->index_lo = row->index_hi = 0.0;
        if (!isnan(point[c]))
            percentile_interval(rep + (size_t)c * PD_SENSITIVITY_RESAMPLES,
                                PD_SENSITIVITY_RESAMPLES, &row->index_lo, &row->index_hi);
        percentile_raw(eff + (size_t)c * PD_SENSITIVITY_RESAMPLES, PD_SENSITIVITY_RESAMPLES,
                       &row->effect_lo, &row->effect_hi);
    }
    free(key);
    free(order);
    free(w);
    free(nb);
    free(n2);
    free(sb);
    free(tot);
    free(rep);
    free(point);
    free(eff);
    free(cnt);
    return st;
}

/* The two-sided normal point shared by the three pairs of a parameter's
 * thirds (Bonferroni: 0.05 / 3 each), Phi^-1(1 - 0.05 / 6). */
#define PD_Z95_THIRDS 2.3940

/* Parameter col's effect on pose c among the drops in third t of
 * parameter other, and its variance by Agresti and Caffo's adjustment (a
 * success and a failure added to each third: a variance that is never 0,
 * for a pose that no drop of a small cell reaches). */
static double cell_effect(const int *cat, const double *q, long n, int i, int other, int t, int c,
                          double *var)
{
    double nn[2] = {0.0, 0.0}, hit[2] = {0.0, 0.0};
    for (long j = 0; j < n; j++) {
        if (third_of(q, j, other) != t)
            continue;
        int u = third_of(q, j, i);
        if (u == 1)
            continue;
        nn[u / 2] += 1.0;
        hit[u / 2] += cat[j] == c;
    }
    *var = 0.0;
    for (int s = 0; s < 2; s++) {
        double p = (hit[s] + 1.0) / (nn[s] + 2.0);
        *var += p * (1.0 - p) / (nn[s] + 2.0);
    }
    return (nn[1] > 0.0 ? hit[1] / nn[1] : 0.0) - (nn[0] > 0.0 ? hit[0] / nn[0] : 0.0);
}

/* For every pose and ordered pair of parameters: whether the first one's
 * effect changes across the second one's thirds, the pair of thirds whose
 * effects differ by the most joint standard errors (beyond PD_Z95_THIRDS
 * to be flagged); of several flagged partners, the one furthest out. */
static int interactions(const int *cat, const double *q, long n, int k, pd_sensitivity *s)
{
    int tests = 0;
    for (int c = 0; c < k; c++)
        for (int col = 0; col < s->nparams; col++) {
            pd_sensitivity_row *row = &s->rows[(size_t)c * (size_t)s->nparams + (size_t)col];
            row->interacts = -1;
            double best = PD_Z95_THIRDS;
            for (int oc = 0; oc < s->nparams; oc++) {
                if (oc == col)
                    continue;
                tests++;
                double e[3], v[3];
                for (int t = 0; t < 3; t++)
                    e[t] = cell_effect(cat, q, n, (int)s->param[col], (int)s->param[oc], t, c,
                                       &v[t]);
                for (int a = 0; a < 3; a++)
                    for (int b = a + 1; b < 3; b++) {
                        double sd = sqrt(v[a] + v[b]), z = fabs(e[b] - e[a]) / sd;
                        if (!(z > best))
                            continue;
                        best = z;
                        row->interacts = (int)s->param[oc];
                        memcpy(row->effect_in, e, sizeof e);
                        row->interaction = e[b] - e[a];
                        row->interaction_lo = e[b] - e[a] - PD_Z95_THIRDS * sd;
                        row->interaction_hi = e[b] - e[a] + PD_Z95_THIRDS * sd;
                    }
            }
        }
    return tests;
}

pd_status pd_sim_sensitivity(const pd_sim_result *r, const pd_scene *sc, double size,
                             const int *class_of, int nclasses, pd_sensitivity **out,
                             pd_diag *diag)
{
    if (!r || !sc || !out)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_sensitivity: NULL argument");
    if (!r->trials && r->n > 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_sensitivity: the run kept no trial records "
                       "(options keep_trials)");
    int k = class_of ? nclasses : r->nposes;
    for (int p = 0; class_of && p < r->nposes; p++)
        if (class_of[p] < 0 || class_of[p] >= nclasses)
            return pd_fail(diag, PD_ERR_USAGE, "pd_sim_sensitivity: pose %d's class %d is not "
                           "one of %d", p + 1, class_of[p] + 1, nclasses);
    if (k < 1)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_sensitivity: no poses");
    pd_sensitivity *s = calloc(1, sizeof *s);
    if (!s)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the sensitivity");
    s->nposes = k;
    for (int i = 0; i < PD_NPARAMS; i++)
        if (pd_scene_varies(sc, (pd_scene_param)i))
            s->param[s->nparams++] = (pd_scene_param)i;
    size_t nt = (size_t)(r->n > 0 ? r->n : 1);
    int *cat = malloc(sizeof *cat * nt);
    double *q = malloc(sizeof *q * nt * PD_NPARAMS);
    s->rows = calloc((size_t)k * (size_t)(s->nparams ? s->nparams : 1), sizeof *s->rows);
    pd_status st = PD_OK;
    if (!cat || !q || !s->rows)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the sensitivity");
    if (st == PD_OK)
        s->n = used_drops(r, sc, size, class_of, cat, q);
    for (int col = 0; st == PD_OK && col < s->nparams; col++) {
        int i = (int)s->param[col];
        for (int c = 0; c < k; c++) {
            pd_sensitivity_row *row = &s->rows[(size_t)c * (size_t)s->nparams + (size_t)col];
            row->pose = c;
            row->param = (pd_scene_param)i;
            thirds(cat, q, s->n, i, c, row);
        }
        if (s->n >= 4)
            st = indices(cat, q, s->n, i, k, col, s->nparams, r->seed, s->rows, diag);
    }
    for (int j = 0; st == PD_OK && j < k * s->nparams; j++) {
        pd_sensitivity_row *row = &s->rows[j];
        row->effect = row->p_high - row->p_low;
        s->resolution = fmax(s->resolution, 0.5 * (row->effect_hi - row->effect_lo));
    }
    if (st == PD_OK)
        s->interaction_tests = interactions(cat, q, s->n, k, s);
    free(cat);
    free(q);
    if (st != PD_OK) {
        pd_sensitivity_free(s);
        return st;
    }
    *out = s;
    return PD_OK;
}
