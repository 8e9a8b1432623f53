/* pose_transform.c: the rigid transform that rests a part on one of its
 * poses (posedrop/static.h). */
#include <math.h>
#include "base/fail.h"
#include "base/vec3.h"
#include "posedrop/static.h"
#include "static/static_tol.h"

pd_status pd_pose_transform(const pd_part *part, const pd_pose *pose, double transform[16],
                            pd_diag *diag)
{
    if (!part || !pose || !transform)
        return pd_fail(diag, PD_ERR_USAGE, "pd_pose_transform: NULL %s",
                       !part ? "part" : !pose ? "pose" : "transform");
    pd_vec3 n = pose->normal;
    if (!v3_isfinite(n))
        return pd_fail(diag, PD_ERR_NONFINITE, "pd_pose_transform: the pose's normal is not "
                       "finite (%g, %g, %g)", n.x, n.y, n.z);
    if (!(fabs(v3_norm(n) - 1.0) <= PD_TOL_POSE_UNIT))
        return pd_fail(diag, PD_ERR_USAGE, "pd_pose_transform: the pose's normal (%g, %g, %g) "
                       "is not a unit vector (length %.17g)", n.x, n.y, n.z, v3_norm(n));
    const pd_hull *h = part->hull;
    if (!h || pose->facet < 0 || pose->facet >= h->nfacets)
        return pd_fail(diag, PD_ERR_RANGE, "pd_pose_transform: facet %d is not one of the "
                       "part's hull's %d", pose->facet, h ? h->nfacets : 0);
    double z[3] = {-n.x, -n.y, -n.z}, x[3] = {-z[1], z[0], 0.0}, y[3];
    double len = sqrt(x[0] * x[0] + x[1] * x[1]);
    if (len < PD_PRINT_ZERO) {
        x[0] = 1.0;
        x[1] = 0.0;
    } else {
        x[0] /= len;
        x[1] /= len;
    }
    y[0] = z[1] * x[2] - z[2] * x[1];
    y[1] = z[2] * x[0] - z[0] * x[2];
    y[2] = z[0] * x[1] - z[1] * x[0];
    double ylen = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    for (int k = 0; k < 3; k++)
        y[k] /= ylen;
    const pd_vec3 o = part->origin;
    double low = INFINITY;
    for (int i = 0; i < h->nverts; i++) {
        double hz = z[0] * (h->verts[i].x + o.x) + z[1] * (h->verts[i].y + o.y) +
                    z[2] * (h->verts[i].z + o.z);
        if (hz < low)
            low = hz;
    }
    const double rows[3][3] = {{x[0], x[1], x[2]}, {y[0], y[1], y[2]}, {z[0], z[1], z[2]}};
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            transform[4 * r + c] = rows[r][c];
        transform[4 * r + 3] = r == 2 ? -low : 0.0;
    }
    transform[12] = transform[13] = transform[14] = 0.0;
    transform[15] = 1.0;
    return PD_OK;
}
