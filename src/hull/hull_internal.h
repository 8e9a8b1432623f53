/* hull_internal.h (private): the stages of pd_hull_build.
 *
 * hull.c classifies the input and picks a starting tetrahedron,
 * hull_tri.c builds the exactly convex triangulated hull (quickhull on exact
 * predicates), hull_merge.c merges its coplanar triangles into the polygonal
 * facets of pd_hull, hull_check.c validates the result. */
#ifndef PD_HULL_INTERNAL_H
#define PD_HULL_INTERNAL_H

#include "posedrop/hull.h"

/* A closed triangulated convex surface over input point indices. */
typedef struct {
    int ntris;
    int (*tri)[3]; /* vertex indices, counter-clockwise seen from outside */
    int (*nb)[3];  /* nb[t][i]: triangle across edge tri[t][i] -> tri[t][(i+1)%3] */
} pd_trihull;

/* Quickhull of pts from the non-degenerate tetrahedron seed[0..3];
 * PD_ERR_CANCELLED when *cancel (may be NULL) is found non-zero, read every
 * thousand or so points added. */
pd_status pd_trihull_build(const pd_vec3 *pts, int npts, const int seed[4], pd_cancel_flag *cancel,
                           pd_trihull *out, pd_diag *diag);

/* pd_hull_build, PD_ERR_CANCELLED when *cancel (may be NULL) is found
 * non-zero during the triangulated hull, where the time of a large part's
 * hull goes. */
pd_status pd_hull_build_cancel(const pd_vec3 *pts, int npts, pd_cancel_flag *cancel, pd_hull **hull,
                               pd_diag *diag);
void pd_trihull_free(pd_trihull *th);

/* What the merge had to repair (hull_merge.c): how often the plane test
 * accepted a triangle that would have made its region other than a disc, and
 * how many regions of two or more triangles were dissolved into single
 * triangles to give every facet three corners. Lets the tests see that they
 * reach those paths. */
typedef struct {
    long disc_rejects;
    long dissolved_regions;
    long dissolved_triangles;
    int repair_passes;
} pd_hull_merge_stats;

/* Merges the triangles of th into the facets of hull (whose size is set);
 * stats may be NULL. */
pd_status pd_hull_merge(const pd_vec3 *pts, const pd_trihull *th, pd_hull *hull, pd_hull_merge_stats *stats,
                        pd_diag *diag);

/* pd_hull_build that also reports the merge's repairs (stats may be NULL). */
pd_status pd_hull_build_stats(const pd_vec3 *pts, int npts, pd_hull **hull, pd_hull_merge_stats *stats,
                              pd_diag *diag);

#endif
