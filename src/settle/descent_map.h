/* descent_map.h (private): where quasi-static descent lands, looked up
 * instead of walked, for the drop's decision test (drop.c), which asks at
 * every pass of its loop. descent_map.c gives the argument. */
#ifndef PD_DESCENT_MAP_H
#define PD_DESCENT_MAP_H

#include "posedrop/hull.h"
#include "posedrop/status.h"
#include "static/static_internal.h"

/* What one star edge's arc answers (descent_map.c). */
typedef struct pd_descent_arc {
    pd_vec3 ma, mb;  /* unit normals of the lune's two planes through v - com */
    pd_vec3 ms;      /* unit normal of the plane through the saddle (or ma) */
    double margin;   /* how far inside all three g must be; INFINITY: never */
    double cone;     /* how far inside this boundary of v's cone, times |u| */
    int pos, neg;    /* facet landed on, ms . g > 0 or < 0; -1: walk */
} pd_descent_arc;

typedef struct pd_descent_map {
    const pd_hull *hull; /* borrowed, as is star: both must outlive the map */
    const pd_star *star;
    pd_vec3 com;
    pd_descent_arc *arc; /* one per star edge */
} pd_descent_map;

/* PD_ERR_NOMEM only. */
pd_status pd_descent_map_build(const pd_hull *hull, const pd_star *star, pd_vec3 com,
                               pd_descent_map *map);
void pd_descent_map_free(pd_descent_map *map);

/* The facet pd_descend lands on from g, whose support vertex is v, when g
 * lies well inside one of the map's regions; else -1. */
int pd_descent_map_facet(const pd_descent_map *map, pd_vec3 g, int v);

/* pd_descend (static_internal.h) for map's hull, star and centre of mass:
 * the same facet and the same support vertex into *hint, from the map when g
 * lies well inside one of its regions, else by pd_descend itself. */
pd_status pd_descent_lookup(const pd_descent_map *map, pd_vec3 g, int *facet, int *hint);

#endif
