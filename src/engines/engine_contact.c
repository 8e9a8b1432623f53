/* engine_contact.c: the spring-dashpot that stands for the scene's contact
 * in the stepping engines (see engine.h). */
#include <math.h>
#include "engines/engine.h"

/* Bisection halvings of zeta's bracket: 200 reach round-off of any bracket. */
enum { CONTACT_LAW_HALVINGS = 200 };

/* The bracket's top: e(zeta) ~ 1 / (2 zeta)^2 for large zeta, 2.5e-7 at
 * 1000, far below PD_ENGINE_E_MIN. */
static const double CONTACT_LAW_ZETA_MAX = 1000.0;

/* Duration of a push-only contact times omega (engine.h). */
static double duration_scaled(double zeta)
{
    const double pi = 3.14159265358979323846;
    if (zeta < 1.0)
        return (pi - 2.0 * asin(zeta)) / sqrt(1.0 - zeta * zeta);
    if (zeta > 1.0)
        return 2.0 * acosh(zeta) / sqrt(zeta * zeta - 1.0);
    return 2.0;
}

static double restitution(double zeta) { return exp(-zeta * duration_scaled(zeta)); }

void pd_engine_contact_law(double T, double e, double *omega, double *zeta)
{
    double target = fmin(1.0, fmax(e, PD_ENGINE_E_MIN));
    double lo = 0.0, hi = CONTACT_LAW_ZETA_MAX;
    for (int i = 0; i < CONTACT_LAW_HALVINGS && lo < hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (restitution(mid) > target)
            lo = mid;
        else
            hi = mid;
    }
    *zeta = target >= 1.0 ? 0.0 : 0.5 * (lo + hi);
    *omega = duration_scaled(*zeta) / T;
}
