/* mesh_internal.h (private): checks shared by the modules that take a mesh. */
#ifndef PD_MESH_INTERNAL_H
#define PD_MESH_INTERNAL_H

#include "posedrop/diag.h"
#include "posedrop/mesh.h"

/* A mesh handed to the library by a caller: non-negative counts, arrays
 * present, triangle indices in range, coordinates finite. who names the
 * calling module in the message ("mass", "orient"). PD_OK, PD_ERR_USAGE,
 * PD_ERR_RANGE or PD_ERR_NONFINITE. */
pd_status pd_mesh_validate(const pd_mesh *m, const char *who, pd_diag *diag);

/* pd_mesh_weld and pd_mesh_orient, PD_ERR_CANCELLED (the mesh as it was)
 * when *cancel (may be NULL) is found non-zero: read every few thousand
 * steps of their loops, so that a large part's build stops within a
 * millisecond or so of the flag. */
pd_status pd_mesh_weld_cancel(pd_mesh *mesh, double tol, int *nmerged, pd_cancel_flag *cancel);
pd_status pd_mesh_orient_cancel(pd_mesh *mesh, int *nflipped, pd_cancel_flag *cancel,
                                pd_diag *diag);

/* Finds two triangles of a welded mesh whose relative interiors cross
 * (exact signs of orientation: sharing a vertex or an edge, or touching
 * without crossing, is not crossing; coplanar pairs are not examined).
 * *ta < *tb are their indices and *at a point of the crossing (rounded), or
 * *ta = *tb = -1 when there is none; *tested (when not NULL) the number of
 * pairs that passed the broad phase (to the plane filter and exact test). PD_OK, PD_ERR_NOMEM, or
 * PD_ERR_CANCELLED when *cancel (may be NULL) is found non-zero (read
 * before the search and every few thousand steps of it). Pairs sharing a
 * vertex are found from the directions about it, the others by a tree of
 * oriented boxes: about n log n for the usual surfaces, long thin triangles
 * across the axes and fans of them about one corner included. */
pd_status pd_mesh_self_crossing(const pd_mesh *m, pd_cancel_flag *cancel, int *ta, int *tb,
                                pd_vec3 *at, size_t *tested);

/* The floating-point filter in front of pd_mesh_self_crossing's exact test:
 * 1 when it proves that one of triangles a and b (corners indexed into v)
 * has no corner strictly on each side of the other's plane, so that they do
 * not cross; 0 when it cannot tell. R at least the largest coordinate
 * magnitude of v. */
int pd_selfx_plane_filter(const pd_vec3 *v, const int a[3], const int b[3], double R);

#endif
