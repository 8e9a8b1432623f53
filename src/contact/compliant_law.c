/* compliant_law.c: the normal law of one compliant contact (see
 * compliant_law.h). */
#include <math.h>
#include "base/gsl_adapter.h"
#include "contact/compliant_law.h"

static int scaled_law(double t, const double y[], double dydt[], void *user)
{
    (void)t;
    double chi = *(const double *)user;
    dydt[0] = y[1];
    dydt[1] = -fmax(0.0, y[0] * (1.0 + chi * y[1]));
    return 0;
}

/* The law with s as the variable: (dt/ds, dv/ds) = (1/v, s''/v). */
static void henon_rhs(double chi, double s, double v, double *kt, double *kv)
{
    *kt = 1.0 / v;
    *kv = -fmax(0.0, s * (1.0 + chi * v)) / v;
}

/* v is far from 0 at the contact's end (it is -e there), so the law in s
 * carries the state from just past s = 0 back onto it exactly (Henon's
 * trick). Classical RK4 over n substeps. */
static void henon_to_zero(double chi, double *t, double *s, double *v, int n)
{
    double ds = -*s / n;
    for (int i = 0; i < n; i++) {
        double k1t, k1v, k2t, k2v, k3t, k3v, k4t, k4v, ss = *s;
        henon_rhs(chi, ss, *v, &k1t, &k1v);
        henon_rhs(chi, ss + 0.5 * ds, *v + 0.5 * ds * k1v, &k2t, &k2v);
        henon_rhs(chi, ss + 0.5 * ds, *v + 0.5 * ds * k2v, &k3t, &k3v);
        henon_rhs(chi, ss + ds, *v + ds * k3v, &k4t, &k4v);
        *t += ds * (k1t + 2.0 * k2t + 2.0 * k3t + k4t) / 6.0;
        *v += ds * (k1v + 2.0 * k2v + 2.0 * k3v + k4v) / 6.0;
        *s = ss + ds;
    }
    *s = 0.0;
}

pd_status pd_compliant_law_contact(double chi, double tol, double *e, double *tau,
                                   double *s_peak)
{
    pd_ode *ode = pd_ode_alloc(2, tol, tol);
    if (!ode)
        return PD_ERR_NOMEM;
    double t = 0.0, h = PD_COMPLIANT_LAW_FIRST_STEP, y[2] = {0.0, 1.0}, dy[2];
    pd_status st = PD_ERR_NO_CONVERGENCE;
    *s_peak = 0.0;
    for (int k = 0; k < PD_COMPLIANT_LAW_MAX_STEPS; k++) {
        double t0 = t, y0[2] = {y[0], y[1]};
        scaled_law(t, y, dy, &chi);
        st = pd_ode_step_from(ode, scaled_law, &chi, &t, t + PD_COMPLIANT_LAW_HORIZON, &h, y, dy);
        if (st != PD_OK)
            break;
        *s_peak = fmax(*s_peak, y[0]);
        if (y[0] <= 0.0 && y[1] < 0.0) {
            /* Past the end: from the step's start, which is inside, along s
             * to s = 0. */
            t = t0;
            y[0] = y0[0];
            y[1] = y0[1];
            henon_to_zero(chi, &t, &y[0], &y[1], PD_COMPLIANT_LAW_HENON_STEPS);
            *e = -y[1];
            *tau = t;
            break;
        }
        st = PD_ERR_NO_CONVERGENCE;
    }
    pd_ode_free(ode);
    return st;
}

/* The rebound of compliant.c's step h on the scaled law, the vertex
 * touching a fraction phase of the step after the step's start: as the run
 * does it, the force from the start's penetration and rate (damping chi over
 * the approach speed 1), clamped at 0, then the penetration from the new
 * rate, until the vertex is out and leaving. -1 if it never leaves within
 * PD_COMPLIANT_LAW_MAX_STEPS (a step far too long). */
static double discrete_rebound(double chi, double h, double phase)
{
    double s = -phase * h, v = 1.0;
    int in = 0;
    for (long k = 0; k < PD_COMPLIANT_LAW_MAX_STEPS; k++) {
        double f = 0.0;
        if (s > 0.0) {
            in = 1;
            f = fmax(0.0, s * (1.0 + chi * v));
        } else if (in && v < 0.0) {
            return -v;
        }
        v -= h * f;
        s += h * v;
    }
    return -1.0;
}

int pd_compliant_law_step_meets(double chi, double e, double h)
{
    for (int i = 0; i < PD_COMPLIANT_STEP_PHASES; i++) {
        double r = discrete_rebound(chi, h, (double)i / PD_COMPLIANT_STEP_PHASES);
        if (r < 0.0 || fabs(r - e) > PD_COMPLIANT_E_TOL)
            return 0;
    }
    return 1;
}

/* The step is the first, going up from steps far inside the tolerance, at
 * which the rebound leaves it: the lowest crossing, not any step that
 * happens to meet it (at e = 1 the cap's step of 1, six steps a period,
 * rebounds exactly, while steps a tenth as long miss by 1e-3), so that the
 * step varies with e as smoothly as the error does and a table of laws can
 * interpolate it. */
pd_status pd_compliant_law_step(double chi, double e, double s_peak, double *step)
{
    const double cap = PD_COMPLIANT_STEP_MAX / (1.0 + chi * s_peak);
    double lo = cap / PD_COMPLIANT_STEP_START, hi = 0.0;
    for (int k = 0; !pd_compliant_law_step_meets(chi, e, lo); k++) {
        if (k == PD_COMPLIANT_STEP_TRIES)
            return PD_ERR_NO_CONVERGENCE;
        lo *= 0.5;
    }
    while (lo < cap) {
        double up = fmin(2.0 * lo, cap);
        if (!pd_compliant_law_step_meets(chi, e, up)) {
            hi = up;
            break;
        }
        lo = up;
    }
    for (int k = 0; hi > 0.0 && hi - lo > PD_COMPLIANT_STEP_REL * lo; k++) {
        if (k == PD_COMPLIANT_STEP_TRIES)
            return PD_ERR_NO_CONVERGENCE;
        double mid = 0.5 * (lo + hi);
        if (pd_compliant_law_step_meets(chi, e, mid))
            lo = mid;
        else
            hi = mid;
    }
    *step = lo;
    return PD_OK;
}

/* One trial of chi: its contact, kept as the answer so far, and
 * *f = e(chi) - e. */
static pd_status trial(double x, double e, double *chi, double *eh, double *tau, double *s_peak,
                       double *f)
{
    pd_status st = pd_compliant_law_contact(x, PD_COMPLIANT_LAW_TOL, eh, tau, s_peak);
    *chi = x;
    *f = *eh - e;
    return st;
}

/* chi solves e(chi) = e, e(chi) falling from 1 at chi = 0 towards 0 and
 * smooth: regula falsi in a bracket, the Illinois way (the value kept at an
 * end that stays is halved, so that both ends close in, superlinearly),
 * where bisection took some 45 contacts of the scaled law. The bracket is
 * ratio (1 +- spread) (1 - e) / e, ratio a guess of chi e / (1 - e) (which
 * lies between 1.01 and 1.5 for every e in range), moved until it holds
 * the root. Each trial is a contact integrated to PD_COMPLIANT_LAW_TOL; the
 * bracket closes to that tolerance as bisection's did, and chi is its last
 * trial, within it. */
static pd_status solve_chi(double e, double ratio, double spread, double *chi, double *eh,
                           double *tau, double *s_peak)
{
    pd_status st;
    double flo, fhi, fx;
    if (e >= 1.0) /* no damping: the undamped oscillator rebounds with e = 1 */
        return trial(0.0, e, chi, eh, tau, s_peak, &fx);
    double lo = ratio * (1.0 - spread) * (1.0 - e) / e, hi = ratio * (1.0 + spread) * (1.0 - e) / e;
    /* A bracket that misses the root moves past the end it missed by
     * twice its width, which doubles each time. */
    double width = hi - lo;
    if ((st = trial(lo, e, chi, eh, tau, s_peak, &flo)) != PD_OK)
        return st;
    while (flo <= 0.0) {
        /* e(lo) at or below e: the root is lower. */
        hi = lo;
        fhi = flo;
        width *= 2.0;
        lo = lo > width ? lo - width : 0.5 * lo;
        if (lo < PD_COMPLIANT_LAW_TOL * PD_COMPLIANT_LAW_TOL)
            return trial(0.0, e, chi, eh, tau, s_peak, &fx);
        if ((st = trial(lo, e, chi, eh, tau, s_peak, &flo)) != PD_OK)
            return st;
    }
    if ((st = trial(hi, e, chi, eh, tau, s_peak, &fhi)) != PD_OK)
        return st;
    while (fhi > 0.0) {
        lo = hi;
        flo = fhi;
        width *= 2.0;
        hi += width;
        if (hi > PD_COMPLIANT_LAW_CHI_MAX)
            return PD_ERR_NO_CONVERGENCE;
        if ((st = trial(hi, e, chi, eh, tau, s_peak, &fhi)) != PD_OK)
            return st;
    }
    /* flo > 0 >= fhi. */
    int kept = 0; /* the end that stayed last time: -1 lo, +1 hi */
    for (int k = 0; hi - lo > PD_COMPLIANT_LAW_TOL * hi; k++) {
        if (k == PD_COMPLIANT_LAW_MAX_TRIALS)
            return PD_ERR_NO_CONVERGENCE;
        double x = hi - fhi * (hi - lo) / (fhi - flo);
        /* Round-off can put the point on an end or outside: bisect. */
        if (!(x > lo && x < hi))
            x = 0.5 * (lo + hi);
        if ((st = trial(x, e, chi, eh, tau, s_peak, &fx)) != PD_OK)
            return st;
        if (fx == 0.0)
            break; /* on the root (a secant can land there exactly) */
        if (fx > 0.0) {
            lo = x;
            flo = fx;
            if (kept == 1)
                fhi *= 0.5;
            kept = 1;
        } else {
            hi = x;
            fhi = fx;
            if (kept == -1)
                flo *= 0.5;
            kept = -1;
        }
    }
    return PD_OK;
}

static pd_status law_init(double e, double T, double ratio, double spread, pd_compliant_law *law)
{
    if (!(e >= 0.0 && e <= 1.0) || !(T > 0.0 && isfinite(T)))
        return PD_ERR_RANGE;
    e = fmax(e, PD_COMPLIANT_E_MIN);
    double eh, tau;
    pd_status st = solve_chi(e, ratio, spread, &law->chi, &eh, &tau, &law->s_peak);
    if (st != PD_OK)
        return st;
    law->e = e;
    law->T = T;
    law->tau = tau;
    law->omega = tau / T;
    return pd_compliant_law_step(law->chi, eh, law->s_peak, &law->step);
}

/* A guess of chi e / (1 - e) (contact_tol.h, PD_COMPLIANT_LAW_CHI_GUESS). */
static double chi_ratio_guess(double e)
{
    return 1.5 - 0.5 * pow(1.0 - fmin(e, 1.0), PD_COMPLIANT_LAW_CHI_GUESS);
}

pd_status pd_compliant_law_init(double e, double T, pd_compliant_law *law)
{
    return law_init(e, T, chi_ratio_guess(fmax(e, PD_COMPLIANT_E_MIN)), PD_COMPLIANT_LAW_CHI_SPREAD,
                    law);
}

/* The table's nodes are even in log e (dense where chi changes fastest,
 * towards e = 0) and hold chi e / (1 - e), which stays between 1.01 and 1.5 over the
 * whole range (chi itself goes as 1 / e towards 0 and as 1 - e towards 1),
 * log tau, s_peak (an estimate at step ends, which only bounds the
 * step) and the log of the step. */
pd_status pd_compliant_table_init(double e_lo, double e_hi, pd_compliant_table *t)
{
    if (!(e_lo >= 0.0 && e_lo <= e_hi && e_hi <= 1.0))
        return PD_ERR_RANGE;
    e_lo = fmax(e_lo, PD_COMPLIANT_E_MIN);
    e_hi = fmax(e_hi, PD_COMPLIANT_E_MIN);
    t->n = e_hi > e_lo ? PD_COMPLIANT_TABLE_NODES : 1;
    t->x_lo = log(e_lo);
    t->dx = t->n > 1 ? (log(e_hi) - t->x_lo) / (t->n - 1) : 0.0;
    for (int i = 0; i < t->n; i++) {
        pd_compliant_law law;
        double e = i == 0 ? e_lo : i + 1 == t->n ? e_hi : exp(t->x_lo + i * t->dx);
        /* From the second node on, chi e / (1 - e) is guessed from the
         * nodes below (extrapolated along the line through the last two),
         * which puts the first bracket within PD_COMPLIANT_TABLE_SPREAD of
         * it and saves about half of each law's contacts. */
        double ratio = i == 0 ? chi_ratio_guess(e)
                       : i == 1 ? t->y[0][0]
                                : 2.0 * t->y[0][i - 1] - t->y[0][i - 2];
        double spread = i == 0 ? PD_COMPLIANT_LAW_CHI_SPREAD : PD_COMPLIANT_TABLE_SPREAD;
        pd_status st = ratio > 0.0 ? law_init(e, 1.0, ratio, spread, &law)
                                   : pd_compliant_law_init(e, 1.0, &law);
        if (st != PD_OK)
            return st;
        t->one = law;
        t->y[0][i] = law.e < 1.0 ? law.chi * law.e / (1.0 - law.e) : 0.0;
        t->y[1][i] = log(law.tau);
        t->y[2][i] = law.s_peak;
        t->y[3][i] = log(law.step);
    }
    /* At e = 1 chi is 0 and the ratio 0 / 0: its limit, extrapolated by
     * the cubic through the four nodes below. */
    int last = t->n - 1;
    if (t->n > 1 && e_hi == 1.0)
        t->y[0][last] = 4.0 * t->y[0][last - 1] - 6.0 * t->y[0][last - 2] +
                        4.0 * t->y[0][last - 3] - t->y[0][last - 4];
    return PD_OK;
}

void pd_compliant_table_law(const pd_compliant_table *t, double e, double T, pd_compliant_law *law)
{
    e = fmax(e, PD_COMPLIANT_E_MIN);
    if (t->n == 1) {
        /* One restitution: its exact law, as pd_compliant_law_init gives
         * it for duration T (chi, tau, s_peak and the step do not
         * depend on T). */
        *law = t->one;
        law->T = T;
        law->omega = law->tau / T;
        return;
    }
    /* Cubic Lagrange interpolation through the four nodes around x, shifted
     * inwards at the ends: error of order dx^4 everywhere. */
    double x = (log(e) - t->x_lo) / t->dx, v[4], w[4];
    int i = (int)floor(x) - 1;
    i = i < 0 ? 0 : i > t->n - 4 ? t->n - 4 : i;
    for (int j = 0; j < 4; j++) {
        w[j] = 1.0;
        for (int k = 0; k < 4; k++)
            if (k != j)
                w[j] *= (x - (i + k)) / (double)(j - k);
    }
    for (int q = 0; q < 4; q++)
        v[q] = w[0] * t->y[q][i] + w[1] * t->y[q][i + 1] + w[2] * t->y[q][i + 2] +
               w[3] * t->y[q][i + 3];
    law->e = e;
    law->T = T;
    law->chi = e < 1.0 ? v[0] * (1.0 - e) / e : 0.0;
    law->tau = exp(v[1]);
    law->s_peak = v[2];
    law->omega = law->tau / T;
    /* The step interpolated, then checked: where there is little damping
     * (e near 1) the rebound's error wavers with the step, and the step
     * found at the nodes with it, so the interpolated step can miss the
     * tolerance (by up to 2.8 times between nodes of a table over 0.01 to
     * 1). Shortened until it meets it; at most a few checks of about 500
     * steps of the scaled law each. */
    double h = exp(v[3]);
    for (int k = 0; k < PD_COMPLIANT_STEP_TRIES && !pd_compliant_law_step_meets(law->chi, e, h); k++)
        h *= PD_COMPLIANT_STEP_SHRINK;
    law->step = h;
}
