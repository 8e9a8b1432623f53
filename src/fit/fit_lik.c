/* fit_lik.c: the smoothed multinomial likelihood and the small statistics
 * the fit reports with (docs/calibration.md). */
#include <math.h>
#include "base/gsl_adapter.h"
#include "fit/fit_engine.h"
#include "posedrop/fit.h"

void pd_fit_smooth(int k, const double *p_sim, double nsim, double alpha, double *out)
{
    if (!p_sim || !out)
        return;
    double den = nsim + (double)k * alpha;
    for (int i = 0; i < k; i++)
        out[i] = (nsim * p_sim[i] + alpha) / den;
}

double pd_fit_loglik(int k, const long *count, const double *p_sim, double nsim, double alpha)
{
    double den = nsim + (double)k * alpha, l = 0.0;
    if (!count || !p_sim)
        return 0.0;
    for (int i = 0; i < k; i++)
        if (count[i] > 0)
            l += (double)count[i] * log((nsim * p_sim[i] + alpha) / den);
    return l;
}

/* Stirling's series is used from this a on: its next term, 1 / (1260 a^5),
 * is then below 1e-13, while GSL's lnpoch loses digits as a grows (5e-9 at
 * a = 1e7, 40 counts, against a sum of logs in long double). */
static const double STIRLING_FROM = 100.0;

/* log Gamma(a + x) - log Gamma(a), a > 0, x >= 0. */
static double lnpoch(double a, double x)
{
    if (a < STIRLING_FROM)
        return pd_gsl_lnpoch(a, x);
    double b = a + x;
    return (a - 0.5) * log1p(x / a) + x * log(b) - x + (1.0 / b - 1.0 / a) / 12.0 -
           (1.0 / (b * b * b) - 1.0 / (a * a * a)) / 360.0;
}

/* The probability of cell j of counts: the sum over its classes (cell_of
 * NULL: class j alone); *members receives their number. */
static double cell_p(int k, const int *cell_of, int j, const double *p, int *members)
{
    if (!cell_of) {
        *members = 1;
        return p[j];
    }
    double s = 0.0;
    *members = 0;
    for (int i = 0; i < k; i++)
        if (cell_of[i] == j) {
            s += p[i];
            (*members)++;
        }
    return s;
}

double fit_loglik_cells(int k, const int *cell_of, int ncells, const long *count,
                        const double *p_sim, double nsim, double alpha)
{
    if (!count || !p_sim)
        return 0.0;
    double l = 0.0;
    long n = 0;
    /* A Dirichlet's sums over disjoint cells are Dirichlet with the summed
     * parameters: a cell of m classes has s + m alpha. */
    for (int j = 0; j < ncells; j++)
        if (count[j] > 0) {
            int m;
            double s = nsim * cell_p(k, cell_of, j, p_sim, &m);
            l += lnpoch(s + (double)m * alpha, (double)count[j]);
            n += count[j];
        }
    return l - lnpoch(nsim + (double)k * alpha, (double)n);
}

double pd_fit_loglik_dm(int k, const long *count, const double *p_sim, double nsim, double alpha)
{
    return fit_loglik_cells(k, NULL, k, count, p_sim, nsim, alpha);
}

double fit_chi2_cells(int k, const int *cell_of, int ncells, const long *count, const double *p)
{
    long n = 0;
    for (int j = 0; j < ncells; j++)
        n += count[j];
    double x2 = 0.0;
    for (int j = 0; j < ncells; j++) {
        int m;
        double e = (double)n * cell_p(k, cell_of, j, p, &m);
        x2 += ((double)count[j] - e) * ((double)count[j] - e) / e;
    }
    return x2;
}

double fit_chi2_two_sample(int k, const int *cell_of, int ncells, const long *count,
                           const double *p, double nsim, int *df)
{
    long n = 0;
    for (int j = 0; j < ncells; j++)
        n += count[j];
    *df = 0;
    if (!(nsim > 0) || n <= 0)
        return 0.0;
    *df = -1;
    double tot = (double)n + nsim, x2 = 0.0;
    for (int j = 0; j < ncells; j++) {
        int m;
        double s = nsim * cell_p(k, cell_of, j, p, &m), both = (double)count[j] + s;
        if (!(both > 0))
            continue;
        (*df)++;
        double em = (double)n * both / tot, es = nsim * both / tot;
        x2 += ((double)count[j] - em) * ((double)count[j] - em) / em + (s - es) * (s - es) / es;
    }
    if (*df < 0)
        *df = 0;
    return x2;
}

double fit_chi2(int k, const long *count, const double *p)
{
    return fit_chi2_cells(k, NULL, k, count, p);
}

double fit_cell_p(int k, const int *cell_of, int j, const double *p)
{
    int m;
    return cell_p(k, cell_of, j, p, &m);
}

double fit_halton(long i, int j)
{
    static const int prime[] = {2, 3, 5, 7, 11, 13, 17};
    double f = 1.0, r = 0.0;
    long b = prime[j];
    for (long n = i; n > 0; n /= b) {
        f /= (double)b;
        r += f * (double)(n % b);
    }
    return r;
}

/* Bisection to this width: far below any probability printed. */
static const double QUANTILE_TOL = 1e-9;

double fit_beta_mixture_quantile(int n, const double *w, const double *a, const double *b,
                                 double q)
{
    double x0 = 0.0, x1 = 1.0;
    while (x1 - x0 > QUANTILE_TOL) {
        double x = 0.5 * (x0 + x1), c = 0.0;
        for (int j = 0; j < n; j++)
            if (w[j] > 0)
                c += w[j] * pd_gsl_beta_p(x, a[j], b[j]);
        if (c < q)
            x0 = x;
        else
            x1 = x;
    }
    return 0.5 * (x0 + x1);
}
