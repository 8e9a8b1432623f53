/* basin.c: the energy barriers between stable poses, which decide when a
 * drop's outcome can no longer change.
 *
 * Resting on the floor with gravity g, the centre of mass is at height h(g),
 * the hull's support function (see topple.c). Its minima are the stable
 * facets; its saddles are the edge equilibria: the centre of mass directly
 * above an edge, its foot inside the segment, the direction to the foot
 * inside the edge's arc between its two facets' normals (along the arc h is
 * at a maximum there, across it h rises as one end of the edge lifts). A
 * basin's component of the sublevel set {h < c} first touches another basin
 * at the lowest saddle on its boundary, and a saddle lies on the boundary
 * between the basins its two descending branches reach: along the arc to
 * either facet, then down the quasi-static graph (descent rule).
 * So a part whose total energy (kinetic plus potential, per unit weight, a
 * height) is below its basin's lowest saddle can never reach another basin:
 * every configuration it can still visit has h(g) <= z_com < barrier. */
#include <math.h>
#include "settle/basin.h"
#include "base/vec3.h"

/* The edge equilibrium of edge (v, w) between facets a and b, if any: the
 * height of the centre of mass balanced on it, else -1. */
static double saddle_height(const pd_hull *h, pd_vec3 com, int v, int w, int a, int b)
{
    pd_vec3 e = v3_sub(h->verts[w], h->verts[v]);
    double lambda = v3_dot(v3_sub(com, h->verts[v]), e) / v3_dot(e, e);
    if (lambda < 0.0 || lambda > 1.0)
        return -1.0;
    pd_vec3 foot = v3_add(h->verts[v], v3_scale(e, lambda));
    pd_vec3 g0 = v3_sub(foot, com);
    /* g0 is perpendicular to e, as both normals are: it lies on the arc
     * between them iff it is a non-negative combination of the two. */
    pd_vec3 na = h->normal[a], nb = h->normal[b];
    double side = v3_dot(v3_cross(na, nb), e);
    if (v3_dot(v3_cross(na, g0), e) * side < 0.0 || v3_dot(v3_cross(g0, nb), e) * side < 0.0)
        return -1.0;
    return v3_norm(g0);
}

void pd_basin_barriers(const pd_hull *h, pd_vec3 com, const pd_static_result *res,
                       double *barrier)
{
    const pd_facet_result *fr = res->facets;
    for (int f = 0; f < h->nfacets; f++)
        barrier[f] = INFINITY;
    for (int a = 0; a < h->nfacets; a++) {
        int base = h->facet_start[a], k = h->facet_start[a + 1] - base;
        for (int i = 0; i < k; i++) {
            int b = h->facet_adj[base + i];
            int ra = fr[a].rest, rb = fr[b].rest;
            if (b < a || ra == rb) /* each edge once; same basin on both sides */
                continue;
            double s = saddle_height(h, com, h->facet_vert[base + i],
                                     h->facet_vert[base + (i + 1) % k], a, b);
            if (s < 0.0)
                continue;
            barrier[ra] = fmin(barrier[ra], s);
            barrier[rb] = fmin(barrier[rb], s);
        }
    }
    /* Every facet carries its basin's barrier, so a caller that knows where
     * the part would land needs no second lookup. */
    for (int f = 0; f < h->nfacets; f++)
        barrier[f] = barrier[fr[f].rest];
}
