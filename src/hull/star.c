/* star.c: the edges around each hull vertex (see star.h). */
#include <stdlib.h>
#include "base/vec3.h"
#include "hull/star.h"

pd_status pd_star_build(const pd_hull *h, pd_star *s)
{
    int nloop = h->facet_start[h->nfacets];
    s->start = calloc((size_t)h->nverts + 1, sizeof *s->start);
    s->edge = malloc(sizeof *s->edge * (size_t)(nloop > 0 ? nloop : 1));
    if (!s->start || !s->edge)
        return PD_ERR_NOMEM;
    for (int k = 0; k < nloop; k++)
        s->start[h->facet_vert[k] + 1]++;
    for (int v = 0; v < h->nverts; v++)
        s->start[v + 1] += s->start[v];
    int *fill = malloc(sizeof *fill * (size_t)(h->nverts > 0 ? h->nverts : 1));
    if (!fill)
        return PD_ERR_NOMEM;
    for (int v = 0; v < h->nverts; v++)
        fill[v] = s->start[v];
    for (int f = 0; f < h->nfacets; f++) {
        int b = h->facet_start[f], n = h->facet_start[f + 1] - b;
        for (int i = 0; i < n; i++) {
            int v = h->facet_vert[b + i];
            pd_star_edge *e = &s->edge[fill[v]++];
            e->to = h->facet_vert[b + (i + 1) % n];
            e->u = v3_sub(h->verts[v], h->verts[e->to]);
            e->len = v3_norm(e->u);
            e->left = f;
            e->right = h->facet_adj[b + i];
        }
    }
    free(fill);
    return PD_OK;
}

void pd_star_free(pd_star *s)
{
    free(s->start);
    free(s->edge);
}

int pd_star_roll(const pd_hull *h, pd_vec3 com, int v, const pd_star_edge *e, pd_vec3 g)
{
    pd_vec3 pv = h->verts[v], pw = h->verts[e->to];
    pd_vec3 tau = v3_unit(v3_cross(v3_sub(pw, pv), g));
    /* dh/ds moving along +tau: both edge ends are support points on the arc. */
    if (v3_dot(v3_sub(pv, com), tau) > 0.0)
        tau = v3_neg(tau);
    return v3_dot(h->normal[e->left], tau) >= v3_dot(h->normal[e->right], tau) ? e->left : e->right;
}

double pd_star_lambda(const pd_hull *h, pd_vec3 com, int v, const pd_star_edge *e)
{
    return -v3_dot(v3_sub(com, h->verts[v]), e->u) / (e->len * e->len);
}

/* Hill-climbing over the vertex graph finds the support vertex, because on a
 * convex polytope a vertex no neighbour of which is farther along g is the
 * farthest of all. */
int pd_star_support(const pd_hull *h, const pd_star *s, pd_vec3 g, int start)
{
    int v = start;
    double best = v3_dot(h->verts[v], g);
    for (int moved = 1; moved;) {
        moved = 0;
        for (int k = s->start[v]; k < s->start[v + 1]; k++) {
            double x = v3_dot(h->verts[s->edge[k].to], g);
            if (x > best) {
                best = x;
                v = s->edge[k].to;
                moved = 1;
                break;
            }
        }
    }
    return v;
}
