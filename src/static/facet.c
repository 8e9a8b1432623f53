/* facet.c: what the centre of mass sees of one hull facet: its area, its
 * height above the facet's plane, and where it projects relative to the
 * facet's polygon (inside, on a knife edge, or beyond an edge or a vertex). */
#include <float.h>
#include "posedrop/tolerances.h"
#include "static/static_internal.h"
#include "base/vec3.h"

double pd_facet_edge_inside(const pd_hull *hull, pd_vec3 com, int f, int i)
{
    const int *loop = hull->facet_vert + hull->facet_start[f];
    int k = hull->facet_start[f + 1] - hull->facet_start[f];
    pd_vec3 a = hull->verts[loop[i]], b = hull->verts[loop[(i + 1) % k]];
    return v3_dot(v3_sub(com, a), v3_unit(v3_cross(hull->normal[f], v3_sub(b, a))));
}

void pd_facet_classify(const pd_hull *hull, pd_vec3 com, int f, facet_geom *g,
                       pd_facet_result *r)
{
    const int *loop = hull->facet_vert + hull->facet_start[f];
    int k = hull->facet_start[f + 1] - hull->facet_start[f];
    pd_vec3 n = hull->normal[f];
    double h = hull->offset[f] - v3_dot(n, com);

    /* Area by the fan from the first corner, projected on the normal: exact
     * for a planar convex loop, and insensitive to the corners' round-off
     * distance from the plane. */
    pd_vec3 c0 = hull->verts[loop[0]];
    double area2 = 0.0;
    for (int i = 1; i + 1 < k; i++)
        area2 += v3_dot(n, v3_cross(v3_sub(hull->verts[loop[i]], c0),
                                    v3_sub(hull->verts[loop[i + 1]], c0)));

    /* Signed distances of the foot from each edge line (positive inside: the
     * loop turns counter-clockwise about n, so inside is n x edge). The
     * distance is measured from com itself, not from the computed foot: the
     * in-plane direction is perpendicular to n, so the two agree exactly in
     * exact arithmetic and com carries one rounding less. */
    double inside = DBL_MAX, best_d2 = DBL_MAX;
    pd_vec3 nearest = c0;
    int best_edge = 0, near_edge = 0, near_vertex = -1;
    for (int i = 0; i < k; i++) {
        pd_vec3 a = hull->verts[loop[i]], b = hull->verts[loop[(i + 1) % k]];
        pd_vec3 e = v3_sub(b, a), ca = v3_sub(com, a);
        double d = pd_facet_edge_inside(hull, com, f, i);
        if (d < inside) {
            inside = d;
            best_edge = i;
        }
        double t = v3_dot(ca, e) / v3_dot(e, e);
        int vert = -1;
        if (t <= 0.0) {
            t = 0.0;
            vert = loop[i];
        } else if (t >= 1.0) {
            t = 1.0;
            vert = loop[(i + 1) % k];
        }
        /* In-plane distance from the foot to the nearest point of the edge. */
        pd_vec3 w = v3_sub(ca, v3_scale(e, t));
        w = v3_sub(w, v3_scale(n, v3_dot(w, n)));
        double d2 = v3_dot(w, w);
        if (d2 < best_d2) {
            best_d2 = d2;
            nearest = v3_add(a, v3_scale(e, t));
            near_edge = i;
            near_vertex = vert;
        }
    }

    double knife = PD_TOL_KNIFE_REL * hull->size;
    g->foot = v3_add(com, v3_scale(n, h));
    g->nearest = inside >= 0.0 ? g->foot : nearest;
    g->inside = inside;
    g->near_edge = near_edge;
    g->near_vertex = near_vertex;
    g->best_edge = best_edge;
    r->area = 0.5 * area2;
    r->height = h;
    r->stable = inside > knife;
    r->knife = !r->stable && inside >= -knife;
}
