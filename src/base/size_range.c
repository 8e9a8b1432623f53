/* size_range.c: refusing parts outside the supported sizes (size_range.h). */
#include <math.h>
#include "base/fail.h"
#include "base/size_range.h"

pd_status pd_size_check(pd_vec3 lo, pd_vec3 hi, const char *what, pd_diag *diag)
{
    double d[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}, m = 0.0;
    for (int i = 0; i < 3; i++)
        m = fmax(m, d[i]);
    if (m == 0.0)
        return PD_OK;
    /* The diagonal scaled by its largest extent, so that it is finite
     * whenever that extent is, even where the sum of squares is not. */
    double s = 0.0;
    for (int i = 0; i < 3; i++)
        s += (d[i] / m) * (d[i] / m);
    double L = m * sqrt(s);
    if (!isfinite(L))
        return pd_fail(diag, PD_ERR_RANGE,
                       "%sthe part's size overflows a double (its coordinates run from %.3g to "
                       "%.3g m); supported sizes are %g to %g m", what,
                       fmin(lo.x, fmin(lo.y, lo.z)), fmax(hi.x, fmax(hi.y, hi.z)), PD_SIZE_MIN,
                       PD_SIZE_MAX);
    if (L > PD_SIZE_MAX || L < PD_SIZE_MIN)
        return pd_fail(diag, PD_ERR_RANGE,
                       "%sthe part's size %.3g m is %s the supported sizes, %g to %g m: products "
                       "of its lengths would %s", what, L, L > PD_SIZE_MAX ? "above" : "below",
                       PD_SIZE_MIN, PD_SIZE_MAX,
                       L > PD_SIZE_MAX ? "overflow a double"
                                       : "underflow to subnormal doubles and lose their digits");
    return PD_OK;
}
