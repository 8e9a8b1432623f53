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
#include "static_internal.h"
#include "vec3.h"

double pd_solid_angle_triangle(pd_vec3 a, pd_vec3 b, pd_vec3 c)
{
    double num = v3_dot(a, v3_cross(v3_sub(b, a), v3_sub(c, a)));
    double la = v3_norm(a), lb = v3_norm(b), lc = v3_norm(c);
    double den = la * lb * lc + v3_dot(a, b) * lc + v3_dot(a, c) * lb + v3_dot(b, c) * la;
    return 2.0 * atan2(num, den);
}

double pd_solid_angle_facet(const pd_hull *hull, pd_vec3 com, int f)
{
    /* A convex polygon fanned from its first corner: every triangle is seen
     * from the same (inner) side, so the pieces add without cancellation. */
    const int *loop = hull->facet_vert + hull->facet_start[f];
    int k = hull->facet_start[f + 1] - hull->facet_start[f];
    pd_vec3 a = v3_sub(hull->verts[loop[0]], com);
    double omega = 0.0;
    for (int i = 1; i + 1 < k; i++)
        omega += pd_solid_angle_triangle(a, v3_sub(hull->verts[loop[i]], com),
                                         v3_sub(hull->verts[loop[i + 1]], com));
    return omega;
}
