/* star.h (private): the edges around each hull vertex, the boundaries of
 * its normal cone on the sphere of gravity directions: what the support
 * search, the quasi-static descent and its lookup walk on. */
#ifndef PD_STAR_H
#define PD_STAR_H

#include "posedrop/hull.h"
#include "posedrop/status.h"

/* The edges leaving each hull vertex, with the facets on either side: the
 * boundaries of the vertex's normal cone on the sphere of directions. */
typedef struct pd_star_edge {
    pd_vec3 u;         /* v - to: the cone's boundary is the plane u . g = 0 */
    double len;        /* |u| */
    int to;            /* the other end */
    int left, right;   /* facet with the edge v -> to in its loop, and the one across */
} pd_star_edge;

typedef struct pd_star {
    int *start;        /* nverts + 1: vertex v's edges are edge[start[v] .. start[v+1]) */
    pd_star_edge *edge;
} pd_star;

pd_status pd_star_build(const pd_hull *hull, pd_star *star); /* PD_ERR_NOMEM */
void pd_star_free(pd_star *star);

/* The hull vertex farthest along g, hill-climbed from vertex start. */
int pd_star_support(const pd_hull *hull, const pd_star *star, pd_vec3 g, int start);

/* Where the foot of com on the line of star edge e of vertex v falls: 0 at v,
 * 1 at e->to. Pivoting about v onto e's arc, the part rolls about the edge
 * when this is below 1, else pivots on about e->to. */
double pd_star_lambda(const pd_hull *hull, pd_vec3 com, int v, const pd_star_edge *e);

/* Rolling about star edge e of vertex v from gravity g on its arc: the facet
 * (e->left or e->right) at the end of the arc the centre of mass descends to. */
int pd_star_roll(const pd_hull *hull, pd_vec3 com, int v, const pd_star_edge *e, pd_vec3 g);

#endif
