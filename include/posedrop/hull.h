/* posedrop/hull.h: the convex hull of a point set, as merged polygonal facets.
 *
 * Built by quickhull on exact orientation predicates, so the triangulated hull
 * is exactly convex; coplanar triangles (within PD_TOL_PLANE_REL of the size)
 * are then merged into polygons, so a cube has 6 facets, and points that lie on
 * a facet or an edge are not vertices. */
#ifndef POSEDROP_HULL_H
#define POSEDROP_HULL_H

#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pd_hull {
    double size;         /* bounding-box diagonal of the input points */
    int nverts;
    pd_vec3 *verts;      /* corner vertices only */
    int *vert_source;    /* index of each vertex in the input points */
    int nfacets;
    pd_vec3 *normal;     /* outward unit normal of each facet */
    double *offset;      /* facet plane: dot(normal, x) == offset */
    int *facet_start;    /* nfacets + 1 entries; facet f's loop is
                            facet_vert[facet_start[f] .. facet_start[f+1]) */
    int *facet_vert;     /* corner indices, counter-clockwise seen from outside */
    int *facet_adj;      /* facet_adj[k]: the facet across the edge from
                            facet_vert[k] to the next corner of the loop */
    double volume;       /* m^3 */
} pd_hull;

/* Convex hull of npts points. Classifies degenerate input first:
 * PD_ERR_TOO_FEW_POINTS (< 4), PD_ERR_NONFINITE, PD_ERR_RANGE (a size, the
 * bounding-box diagonal, outside 1e-30 to 1e30 m: docs/limits.md), PD_ERR_COLOCATED,
 * PD_ERR_COLLINEAR, PD_ERR_COPLANAR; also PD_ERR_NOMEM, PD_ERR_INTERNAL.
 * On success *hull is owned by the caller (pd_hull_free). */
PD_API pd_status pd_hull_build(const pd_vec3 *pts, int npts, pd_hull **hull, pd_diag *diag);

/* Validates a hull: unit normals, loops of >= 3 corners, each corner on its
 * facet plane, convexity at every edge, symmetric adjacency, Euler's formula,
 * and (when pts != NULL) every input point inside or on the hull, all within
 * PD_TOL_PLANE_REL. PD_OK or PD_ERR_INTERNAL with the failed check in diag;
 * PD_ERR_USAGE for a NULL hull or a negative npts. */
PD_API pd_status pd_hull_check(const pd_hull *hull, const pd_vec3 *pts, int npts, pd_diag *diag);

PD_API void pd_hull_free(pd_hull *hull);

#ifdef __cplusplus
}
#endif
#endif
