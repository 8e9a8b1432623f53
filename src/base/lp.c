/* lp.c: Seidel's randomized incremental linear program (see lp.h).
 *
 * The optimum over the box alone is a corner of the box; constraints are
 * added one at a time, and when one is violated by the current optimum the
 * new optimum lies on its plane: one variable is eliminated through that
 * plane (the one of largest coefficient) and the program over the earlier
 * constraints, in one dimension fewer, gives it. With the constraints in
 * random order, constraint i is violated with probability at most d / i,
 * so the expected work is linear in their number for a fixed dimension. */
#include "base/lp.h"
#include <math.h>
#include <stdlib.h>

static int solve_1d(const pd_lp_halfspace *h, int k, double c, double lo, double hi, double tol,
                    double *y)
{
    for (int i = 0; i < k; i++) {
        double a = h[i].a[0], b = h[i].b;
        if (a > 0.0)
            hi = fmin(hi, b / a);
        else if (a < 0.0)
            lo = fmax(lo, b / a);
        else if (b < -tol)
            return 0;
    }
    if (!(lo <= hi + tol))
        return 0;
    *y = lo > hi ? 0.5 * (lo + hi) : c > 0.0 ? hi : c < 0.0 ? lo : 0.5 * (lo + hi);
    return 1;
}

int pd_lp_solve(int d, const pd_lp_halfspace *h, int k, const double *c, const double *lo,
                const double *hi, double tol, double *y)
{
    if (d == 1)
        return solve_1d(h, k, c[0], lo[0], hi[0], tol, y);
    for (int j = 0; j < d; j++)
        y[j] = c[j] > 0.0 ? hi[j] : c[j] < 0.0 ? lo[j] : 0.5 * (lo[j] + hi[j]);
    for (int i = 0; i < k; i++) {
        const double *a = h[i].a;
        double s = 0.0;
        for (int j = 0; j < d; j++)
            s += a[j] * y[j];
        if (s <= h[i].b + tol)
            continue;
        int p = 0;
        for (int j = 1; j < d; j++)
            if (fabs(a[j]) > fabs(a[p]))
                p = j;
        if (a[p] == 0.0)
            return 0;
        /* y[p] = q - sum g[j] y[j] on the plane; the others keep their
         * indices with p taken out. */
        double g[PD_LP_MAXDIM], q = h[i].b / a[p], c2[PD_LP_MAXDIM], lo2[PD_LP_MAXDIM],
                                hi2[PD_LP_MAXDIM], y2[PD_LP_MAXDIM];
        int idx[PD_LP_MAXDIM], n = 0;
        for (int j = 0; j < d; j++)
            if (j != p) {
                idx[n] = j;
                g[n] = a[j] / a[p];
                c2[n] = c[j] - c[p] * g[n];
                lo2[n] = lo[j];
                hi2[n] = hi[j];
                n++;
            }
        pd_lp_halfspace *sub = malloc(sizeof *sub * ((size_t)i + 2));
        if (!sub)
            return -1;
        /* y[p] <= hi[p] and y[p] >= lo[p] first, then the earlier ones. */
        for (int m = 0; m < n; m++) {
            sub[0].a[m] = -g[m];
            sub[1].a[m] = g[m];
        }
        sub[0].b = hi[p] - q;
        sub[1].b = q - lo[p];
        for (int r = 0; r < i; r++) {
            for (int m = 0; m < n; m++)
                sub[r + 2].a[m] = h[r].a[idx[m]] - h[r].a[p] * g[m];
            sub[r + 2].b = h[r].b - h[r].a[p] * q;
        }
        int st = pd_lp_solve(n, sub, i + 2, c2, lo2, hi2, tol, y2);
        free(sub);
        if (st != 1)
            return st;
        double yp = q;
        for (int m = 0; m < n; m++) {
            y[idx[m]] = y2[m];
            yp -= g[m] * y2[m];
        }
        y[p] = yp;
    }
    return 1;
}
