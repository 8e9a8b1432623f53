/* markov.c: the long-run distribution of the estimated pose-to-pose chain
 * and its resampling intervals (see markov.h).
 *
 * Exact rather than iterated: mu0 P^t need not converge (a periodic chain
 * swings for ever) and its Cesaro mean converges only as 1/T, so no number of
 * power iterations gives the limit to a known accuracy. Instead the chain is
 * cut into its closed communicating classes (Tarjan's strongly connected
 * components), each class's stationary distribution is solved exactly, and
 * the classes are weighed by the probability that the chain started from mu0
 * is absorbed into each. Both solves are subtraction-free eliminations
 * (Grassmann, Taksar and Heyman 1985; the state reduction of Sheskin 1985):
 * every quantity stays a sum of products of non-negative numbers, so the
 * result has full relative accuracy even for probabilities many orders of
 * magnitude apart, where Gaussian elimination on I - P would cancel. */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/gsl_adapter.h"
#include "sim/markov.h"
#include "posedrop/tolerances.h"
#include "sim/sim_tol.h"

/* Two blocks, carved into the arrays below: ints and doubles. */
struct pd_markov_work {
    int k;
    int *reach, *list;           /* reachable flags; states in visiting order */
    int *comp, *idx, *low, *next, *stack, *calls; /* Tarjan */
    int *cls;                    /* per component: closed-class number, or -1 */
    int *pos;                    /* per state: its row in the reduction */
    double *Q;                   /* k x k: one class's matrix for GTH */
    double *R;                   /* k x 2k: transient rows for the state reduction */
    double *mass;                /* 2k: mu0's mass during the reduction */
};

pd_markov_work *pd_markov_work_alloc(int k)
{
    if (k < 1)
        return NULL;
    pd_markov_work *w = malloc(sizeof *w);
    size_t n = (size_t)k;
    int *ints = malloc(10 * n * sizeof *ints);
    double *doubles = malloc((3 * n * n + 2 * n) * sizeof *doubles);
    if (!w || !ints || !doubles) {
        free(w);
        free(ints);
        free(doubles);
        return NULL;
    }
    w->k = k;
    int **parts[] = {&w->reach, &w->list, &w->comp, &w->idx, &w->low,
                     &w->next,  &w->stack, &w->calls, &w->cls, &w->pos};
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++)
        *parts[i] = ints + i * n;
    w->Q = doubles;
    w->R = doubles + n * n;
    w->mass = doubles + 3 * n * n;
    return w;
}

void pd_markov_work_free(pd_markov_work *w)
{
    if (!w)
        return;
    free(w->reach);
    free(w->Q);
    free(w);
}

/* Marks the states reachable from mu0's support through entries > 0 and
 * lists them in w->list; returns their number, or -1 if one of them has a
 * row without any entry (the chain is undefined there). Rows of unreachable
 * states are never read, so a caller may leave them empty. */
static int reach(pd_markov_work *w, const double *P, const double *mu0)
{
    int k = w->k, n = 0;
    for (int i = 0; i < k; i++) {
        w->reach[i] = mu0[i] > 0.0;
        if (w->reach[i])
            w->list[n++] = i;
    }
    for (int h = 0; h < n; h++) {
        const double *row = P + (size_t)w->list[h] * (size_t)k;
        int any = 0;
        for (int j = 0; j < k; j++) {
            if (!(row[j] > 0.0))
                continue;
            any = 1;
            if (!w->reach[j]) {
                w->reach[j] = 1;
                w->list[n++] = j;
            }
        }
        if (!any)
            return -1;
    }
    return n;
}

/* Tarjan's strongly connected components of the reachable states, without
 * recursion (a chain of thousands of poses must not exhaust the stack).
 * w->comp gets each state's component; returns their number. */
static int components(pd_markov_work *w, const double *P)
{
    int k = w->k, counter = 0, ncomp = 0, top = 0;
    for (int i = 0; i < k; i++) {
        w->idx[i] = -1;
        w->comp[i] = -1;
    }
    for (int s = 0; s < k; s++) {
        if (!w->reach[s] || w->idx[s] >= 0)
            continue;
        int ncalls = 0;
        w->idx[s] = w->low[s] = counter++;
        w->next[s] = 0;
        w->stack[top++] = s;
        w->calls[ncalls++] = s;
        while (ncalls > 0) {
            int v = w->calls[ncalls - 1];
            if (w->next[v] < k) {
                int u = w->next[v]++;
                if (!(P[(size_t)v * (size_t)k + (size_t)u] > 0.0))
                    continue;
                if (w->idx[u] < 0) {
                    w->idx[u] = w->low[u] = counter++;
                    w->next[u] = 0;
                    w->stack[top++] = u;
                    w->calls[ncalls++] = u;
                } else if (w->comp[u] < 0 && w->idx[u] < w->low[v]) {
                    w->low[v] = w->idx[u]; /* u is on the stack */
                }
                continue;
            }
            ncalls--;
            if (ncalls > 0 && w->low[v] < w->low[w->calls[ncalls - 1]])
                w->low[w->calls[ncalls - 1]] = w->low[v];
            if (w->low[v] == w->idx[v]) {
                int u;
                do {
                    u = w->stack[--top];
                    w->comp[u] = ncomp;
                } while (u != v);
                ncomp++;
            }
        }
    }
    return ncomp;
}

/* Stationary distribution x (s entries, sums to 1) of the irreducible chain
 * Q (s x s, row-major, overwritten) by the GTH algorithm: state n is
 * eliminated by censoring (paths through it are folded into the others'
 * rows), where the probability of leaving n is the sum of its off-diagonal
 * entries, never 1 - Q[n][n]. Returns 0 if a state has no way out, which an
 * irreducible chain of two or more states cannot have. */
static int gth(double *Q, int s, double *x)
{
    size_t S = (size_t)s;
    for (int n = s - 1; n > 0; n--) {
        double out = 0.0;
        for (int j = 0; j < n; j++)
            out += Q[(size_t)n * S + (size_t)j];
        if (!(out > 0.0))
            return 0;
        for (int i = 0; i < n; i++) {
            double f = Q[(size_t)i * S + (size_t)n] /= out;
            if (f != 0.0)
                for (int j = 0; j < n; j++)
                    Q[(size_t)i * S + (size_t)j] += f * Q[(size_t)n * S + (size_t)j];
        }
    }
    double total = x[0] = 1.0;
    for (int j = 1; j < s; j++) {
        double v = 0.0;
        for (int i = 0; i < j; i++)
            v += x[i] * Q[(size_t)i * S + (size_t)j];
        x[j] = v;
        total += v;
    }
    for (int j = 0; j < s; j++)
        x[j] /= total;
    return 1;
}

/* Absorption: mass[t + c] receives the probability that the chain started
 * from mu0 ends in closed class c. The t transient states are eliminated one
 * by one (state reduction): the mass on state n and every path through it
 * are passed on in proportion to n's ways out, whose total is again a sum of
 * off-diagonal entries. Returns 0 if a transient state has no way out (it
 * would then not be transient: a bug). */
static int absorb(pd_markov_work *w, int t, int nc)
{
    size_t W = (size_t)(t + nc);
    double *R = w->R, *m = w->mass;
    for (int n = t - 1; n >= 0; n--) {
        const double *rn = R + (size_t)n * W;
        double out = 0.0;
        for (size_t j = 0; j < W; j++)
            if (j != (size_t)n)
                out += rn[j];
        if (!(out > 0.0))
            return 0;
        if (m[n] != 0.0) {
            for (size_t j = 0; j < W; j++)
                if (j != (size_t)n)
                    m[j] += m[n] * (rn[j] / out);
            m[n] = 0.0;
        }
        for (int i = 0; i < n; i++) {
            double *ri = R + (size_t)i * W, f = ri[n] / out;
            if (f == 0.0)
                continue;
            ri[n] = 0.0;
            for (size_t j = 0; j < W; j++)
                if (j != (size_t)n)
                    ri[j] += f * rn[j];
        }
    }
    return 1;
}

pd_status pd_markov_limit(pd_markov_work *w, const double *P, const double *mu0, double *pi,
                          int *nclosed)
{
    int k = w->k;
    size_t K = (size_t)k;
    if (reach(w, P, mu0) < 0)
        return PD_ERR_USAGE;
    int ncomp = components(w, P);
    /* A component is closed when no entry leads out of it. */
    for (int c = 0; c < ncomp; c++)
        w->cls[c] = 1;
    for (int v = 0; v < k; v++)
        for (int u = 0; w->reach[v] && u < k; u++)
            if (P[(size_t)v * K + (size_t)u] > 0.0 && w->comp[u] != w->comp[v])
                w->cls[w->comp[v]] = 0;
    int nc = 0;
    for (int c = 0; c < ncomp; c++)
        w->cls[c] = w->cls[c] ? nc++ : -1;
    /* Transient states become rows 0..t-1 of the reduction, each closed
     * class c one absorbing column t + c. */
    int t = 0;
    for (int v = 0; v < k; v++)
        if (w->reach[v] && w->cls[w->comp[v]] < 0)
            w->pos[v] = t++;
    size_t W = (size_t)(t + nc);
    memset(w->mass, 0, W * sizeof *w->mass);
    memset(w->R, 0, (size_t)t * W * sizeof *w->R);
    for (int v = 0; v < k; v++) {
        if (!w->reach[v])
            continue;
        int c = w->cls[w->comp[v]];
        w->mass[c < 0 ? w->pos[v] : t + c] += mu0[v];
        if (c >= 0)
            continue;
        for (int u = 0; u < k; u++) {
            double p = P[(size_t)v * K + (size_t)u];
            if (p > 0.0) {
                int cu = w->cls[w->comp[u]];
                w->R[(size_t)w->pos[v] * W + (cu < 0 ? (size_t)w->pos[u] : (size_t)(t + cu))] += p;
            }
        }
    }
    if (!absorb(w, t, nc))
        return PD_ERR_INTERNAL;
    /* Each closed class: its own stationary distribution, times its share. */
    for (int v = 0; v < k; v++)
        pi[v] = 0.0;
    for (int c = 0; c < ncomp; c++) {
        int cc = w->cls[c], s = 0;
        if (cc < 0)
            continue;
        for (int v = 0; v < k; v++)
            if (w->comp[v] == c)
                w->list[s++] = v;
        for (int i = 0; i < s; i++)
            for (int j = 0; j < s; j++)
                w->Q[(size_t)i * (size_t)s + (size_t)j] =
                    P[(size_t)w->list[i] * K + (size_t)w->list[j]];
        double *x = w->mass + W; /* W <= k, so this half is free */
        if (!gth(w->Q, s, x))
            return PD_ERR_INTERNAL;
        for (int i = 0; i < s; i++)
            pi[w->list[i]] = w->mass[t + cc] * x[i];
    }
    /* The shares sum to 1 up to round-off of the reduction; renormalised so
     * that pi is a distribution to the last bit. */
    double total = 0.0;
    for (int v = 0; v < k; v++)
        total += pi[v];
    if (!(total > 0.0))
        return PD_ERR_INTERNAL;
    for (int v = 0; v < k; v++)
        pi[v] /= total;
    *nclosed = nc;
    return PD_OK;
}

/* --- estimation from counts ------------------------------------------------ */

/* p (nclasses) = v (k) summed over the classes. */
static void class_sums(const double *v, int k, const int *class_of, int nclasses, double *p)
{
    for (int c = 0; c < nclasses; c++)
        p[c] = 0.0;
    for (int i = 0; i < k; i++)
        p[class_of ? class_of[i] : i] += v[i];
}

/* x (n) = counts (n) / their sum; all zero when there are no counts. */
static void normalise(const long *counts, int n, double *x)
{
    long total = 0;
    for (int i = 0; i < n; i++)
        total += counts[i];
    for (int i = 0; i < n; i++)
        x[i] = total > 0 ? (double)counts[i] / (double)total : 0.0;
}

/* Redraws a distribution estimated from counts (n of them, total drops) as
 * the outcome of as many drops from the estimate smoothed by `extra`
 * pseudo-drops on each pose flagged in known. */
static void redraw(pd_rng *rng, const long *counts, int n, const int *known, double extra,
                   double *weights, unsigned *draw, double *x)
{
    long total = 0;
    for (int i = 0; i < n; i++) {
        total += counts[i];
        weights[i] = (double)counts[i] + (known[i] ? extra : 0.0);
    }
    if (total == 0) {
        memset(x, 0, (size_t)n * sizeof *x);
        return;
    }
    pd_gsl_multinomial(rng, n, (unsigned)total, weights, draw);
    for (int i = 0; i < n; i++)
        x[i] = (double)draw[i] / (double)total;
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile of sorted x[0..n) interpolated between order statistics
 * (Hyndman and Fan's type 7, R's default). */
static double quantile(const double *x, int n, double q)
{
    double h = q * (double)(n - 1);
    int i = (int)h;
    return i + 1 < n ? x[i] + (h - (double)i) * (x[i + 1] - x[i]) : x[n - 1];
}

/* Redraws: drop streams are indexed from 0 upwards by drop number, so the
 * resampling takes its streams from the top of the 64-bit range, which no
 * drop index (a long) can reach. */
static uint64_t resample_stream(int b) { return UINT64_MAX - (uint64_t)b; }

pd_status pd_markov_estimate(const pd_markov_counts *in, const int *class_of, int nclasses,
                             uint64_t seed, pd_markov_summary *out)
{
    int k = in->k;
    size_t K = (size_t)k;
    /* GSL draws multinomials of an unsigned total. */
    for (int i = 0; i <= k; i++) {
        const long *row = i == 0 ? in->first : in->C + (size_t)(i - 1) * K;
        unsigned long total = 0;
        for (int j = 0; j < k; j++)
            total += (unsigned long)row[j];
        if (total > UINT_MAX)
            return PD_ERR_RANGE;
    }
    enum { B = PD_STATIONARY_RESAMPLES };
    pd_markov_work *w = pd_markov_work_alloc(k);
    double *P = malloc(K * K * sizeof *P), *mu0 = malloc(K * sizeof *mu0),
           *pi = malloc(K * sizeof *pi), *weights = malloc(K * sizeof *weights),
           *draws = malloc((size_t)nclasses * B * sizeof *draws),
           *cp = malloc((size_t)nclasses * sizeof *cp), *cm = malloc((size_t)nclasses * sizeof *cm);
    unsigned *draw = malloc(K * sizeof *draw);
    int *known = malloc(K * sizeof *known);
    pd_status st = PD_OK;
    if (!w || !P || !mu0 || !pi || !weights || !draws || !cp || !cm || !draw || !known) {
        st = PD_ERR_NOMEM;
        goto done;
    }
    normalise(in->first, k, mu0);
    for (int i = 0; i < k; i++)
        normalise(in->C + (size_t)i * K, k, P + (size_t)i * K);
    int nclosed = 0;
    out->nclosed = 0;
    if (reach(w, P, mu0) <= 0)
        goto done; /* no uniform drop settled, or a reached row is empty */
    st = pd_markov_limit(w, P, mu0, pi, &nclosed);
    if (st != PD_OK)
        goto done;
    class_sums(pi, k, class_of, nclasses, cp);
    class_sums(mu0, k, class_of, nclasses, cm);
    double tv = 0.0;
    for (int c = 0; c < nclasses; c++)
        tv += fabs(cp[c] - cm[c]);
    /* Parametric bootstrap: mu0 and every row of P are redrawn as the
     * multinomial outcome of as many drops as they were estimated from, and
     * pi is solved again; the 2.5% and 97.5% points of the redrawn pi are
     * the interval. It carries the sampling noise of every row through the
     * chain, which no per-pose binomial interval can (pi depends on all rows
     * at once). The redraws come from the counts plus
     * PD_STATIONARY_PSEUDO_DROPS spread over the poses: redrawn from the
     * counts alone, a transition no drop made could never appear, so a pose
     * that kept all its m drops would stay a trap in every redraw and its
     * interval would collapse to a point, although escapes of probability
     * up to ~3/m are as consistent with the data (tolerances.h gives the
     * coverage measured either way). The pseudo-drops go only to poses
     * with drops started on them, so a redrawn chain never reaches a pose
     * without a row. */
    int nknown = 0;
    for (int i = 0; i < k; i++) {
        long t = 0;
        for (int j = 0; j < k; j++)
            t += in->C[(size_t)i * K + (size_t)j];
        known[i] = t > 0;
        nknown += known[i];
    }
    double extra = PD_STATIONARY_PSEUDO_DROPS / nknown;
    for (int b = 0; b < B; b++) {
        pd_rng rng;
        pd_rng_init(&rng, seed, resample_stream(b));
        redraw(&rng, in->first, k, known, extra, weights, draw, mu0);
        for (int i = 0; i < k; i++)
            redraw(&rng, in->C + (size_t)i * K, k, known, extra, weights, draw, P + (size_t)i * K);
        int nb;
        st = pd_markov_limit(w, P, mu0, pi, &nb);
        if (st != PD_OK)
            goto done;
        class_sums(pi, k, class_of, nclasses, cm);
        for (int c = 0; c < nclasses; c++)
            draws[(size_t)c * B + (size_t)b] = cm[c];
    }
    /* The pseudo-drops pull the redraws of a probability near 0 (a pose
     * whose inflow few drops showed) up, so far that the percentile interval
     * can pass above the estimate itself; it is then stretched down to it,
     * which only adds coverage, and no reported p lies outside its own
     * interval. */
    for (int c = 0; c < nclasses; c++) {
        double *x = draws + (size_t)c * B;
        qsort(x, B, sizeof *x, compare_double);
        out->lo[c] = fmin(quantile(x, B, 0.025), cp[c]);
        out->hi[c] = fmax(quantile(x, B, 0.975), cp[c]);
        out->p[c] = cp[c];
    }
    out->nclosed = nclosed;
    out->shift = 0.5 * tv;
done:
    pd_markov_work_free(w);
    free(P);
    free(mu0);
    free(pi);
    free(weights);
    free(draws);
    free(cp);
    free(cm);
    free(draw);
    free(known);
    return st;
}
