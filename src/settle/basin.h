/* basin.h (private): energy barriers between the stable poses' basins. */
#ifndef PD_BASIN_H
#define PD_BASIN_H

#include "posedrop/hull.h"
#include "posedrop/static.h"

/* For every facet f, barrier[f] (nfacets entries) receives the lowest height
 * of the centre of mass above the floor at which the part can balance on an
 * edge between the basin of res->facets[f].rest and another basin: its
 * energy barrier, in metres (energy per unit weight). INFINITY when that
 * basin has no neighbour (the part has one stable pose). res must come from
 * the descent rule, whose rest[] is the exact quasi-static motion. */
void pd_basin_barriers(const pd_hull *hull, pd_vec3 com, const pd_static_result *res,
                       double *barrier);

#endif
