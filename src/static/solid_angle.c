/* solid_angle.c: solid angles of triangles and hull facets.
 *
 * Van Oosterom and Strackee (1983): for a triangle abc seen from the origin,
 *   tan(omega / 2) = [a b c] / (|a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|).
 * The paper's route (law of cosines for the arcs, then the spherical law of
 * cosines for the angles) takes acos of numbers near 1 and loses about half the
 * digits for a small facet far away; this form keeps full relative precision
 * provided the triple product is formed from edge vectors: a . ((b-a) x (c-a))
 * is computed from differences that are exact-ish for small triangles, whereas
 * a . (b x c) cancels catastrophically when a, b, c are nearly parallel. The
 * denominator is a sum of positive terms whenever the triangle subtends less
 * than a hemisphere, so it has no cancellation either; atan2 covers the rest. */
#include "posedrop/static.h"
#include "static/static_internal.h"
#include "base/vec3.h"

double pd_solid_angle_triangle(pd_vec3 a, pd_vec3 b, pd_vec3 c)
{
    double num = v3_dot(a, v3_cross(v3_sub(b, a), v3_sub(c, a)));
    double la = v3_norm(a), lb = v3_norm(b), lc = v3_norm(c);
    double den = la * lb * lc + v3_dot(a, b) * lc + v3_dot(a, c) * lb + v3_dot(b, c) * la;
    return 2.0 * atan2(num, den);
}

/* The atan2 form's denominator cancels when two corners are nearly opposite
 * as seen from the origin: a large facet seen from close by, fanned from a
 * corner (a 1 x 0.8 tile seen from 5e-5 loses 1e-12 that way). Fanning from
 * the facet's point q nearest the origin avoids it: for any facet points x, y,
 * (x - q) . q >= 0, so a.b and a.c are positive, and b.c is too once every
 * triangle whose angle at q is obtuse is split at the foot of the
 * perpendicular from q onto its far edge. Then the denominator is a sum of
 * non-negative terms and every triangle keeps full relative precision. */
double pd_solid_angle_from_nearest(pd_vec3 q, pd_vec3 b, pd_vec3 c)
{
    pd_vec3 qb = v3_sub(b, q), qc = v3_sub(c, q);
    if (v3_dot(qb, qc) >= 0.0)
        return pd_solid_angle_triangle(q, b, c);
    pd_vec3 e = v3_sub(c, b);
    pd_vec3 foot = v3_add(b, v3_scale(e, v3_dot(v3_neg(qb), e) / v3_dot(e, e)));
    return pd_solid_angle_triangle(q, b, foot) + pd_solid_angle_triangle(q, foot, c);
}

double pd_solid_angle_facet(const pd_hull *hull, pd_vec3 com, int f, pd_vec3 nearest)
{
    const int *loop = hull->facet_vert + hull->facet_start[f];
    int k = hull->facet_start[f + 1] - hull->facet_start[f];
    pd_vec3 q = v3_sub(nearest, com);
    double omega = 0.0;
    for (int i = 0; i < k; i++)
        omega += pd_solid_angle_from_nearest(q, v3_sub(hull->verts[loop[i]], com),
                                             v3_sub(hull->verts[loop[(i + 1) % k]], com));
    return omega;
}
