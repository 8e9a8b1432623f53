/* symmetry_search.h (private): the search for the rotations of a part's hull
 * about its centre of mass, shared by pd_symmetry_find and pd_pose_classes,
 * and the two methods it runs by (the exhaustive one is kept as the tests'
 * and the benchmark's reference). */
#ifndef PD_SYMMETRY_SEARCH_H
#define PD_SYMMETRY_SEARCH_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/part.h"
#include "posedrop/static.h"
#include "posedrop/status.h"
#include "posedrop/symmetry.h"

typedef enum {
    /* Every candidate rotation checked vertex by vertex: O(n) per rotation
     * of the group, so O(n^2) for a body of revolution of n vertices. */
    PD_SYMMETRY_EXHAUSTIVE,
    /* The same rotations, in the same order, with the same matrices: only
     * the candidates that the rotations already found do not generate are
     * checked vertex by vertex, the rest are generated and certified by an
     * error bound (symmetry_search.c says how). */
    PD_SYMMETRY_GENERATED
} pd_symmetry_method;

/* Called once per rotation, the identity first. perm[v] is the hull vertex
 * that R sends vertex v onto (the nearest within PD_TOL_SYMMETRY_REL); under
 * PD_SYMMETRY_GENERATED it is NULL for a rotation certified as a product of
 * rotations reported with their perm (every generator, and every rotation
 * checked vertex by vertex, comes with it). order is the rotation's place
 * in the exhaustive search's order (0 for the identity, the others
 * increasing and distinct): PD_SYMMETRY_EXHAUSTIVE reports them in that
 * order, PD_SYMMETRY_GENERATED in another, so a caller listing them sorts
 * by it. Returns 0 to stop the search. */
typedef int (*pd_rotation_fn)(void *user, const double R[3][3], const int *perm,
                              uint64_t order);

/* Runs the search. *capped is set when the candidates exceed
 * PD_SYMMETRY_MAX_PAIRS (only the identity is reported, with a warning).
 * PD_ERR_NOMEM, also when found() stopped the search. */
pd_status pd_symmetry_search(const pd_part *part, pd_symmetry_method method, pd_rotation_fn found,
                             void *user, int *capped, pd_diag *diag);

/* Puts n rotations in the exhaustive search's order, given each one's order
 * as reported. 0: out of memory (rot unchanged). */
int pd_symmetry_sort(double (*rot)[3][3], const uint64_t *order, int n);

/* pd_symmetry_find and pd_pose_classes by a given method: for the tests and
 * the benchmark, which compare the two. */
pd_status pd_symmetry_find_by(const pd_part *part, pd_symmetry_method method,
                              pd_symmetry **symmetry, pd_diag *diag);
pd_status pd_pose_classes_by(const pd_part *part, const pd_static_result *res,
                             pd_symmetry_method method, int *class_of, int *nclasses,
                             pd_diag *diag);

#endif
