/* posedrop/symmetry.h: pose classes under the part's rotational symmetry.
 *
 * Two stable poses are one class when a proper rotation about the centre of
 * mass maps the hull onto itself and one resting facet onto the other: the
 * part then lies on the floor the same way in both, so the paper's tables
 * count a prism's sides as one pose. Mirror images are never merged (a
 * reflection is not a motion of a rigid part). */
#ifndef POSEDROP_SYMMETRY_H
#define POSEDROP_SYMMETRY_H

#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/part.h"
#include "posedrop/sim.h"
#include "posedrop/static.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The rotations of a part's hull about its centre of mass. */
typedef struct pd_symmetry {
    int nrotations;             /* >= 1 */
    double (*rotation)[3][3];   /* row-major, acting on x - com; rotation[0] is
                                   the identity, the rest in no promised order */
    int capped;                 /* 1: the search was skipped (too many candidate
                                   frames, see PD_SYMMETRY_MAX_PAIRS) and only
                                   the identity is listed; a warning says so */
} pd_symmetry;

/* Finds every proper rotation R (det +1) with R(hull - com) = hull - com,
 * vertex onto vertex within PD_TOL_SYMMETRY_REL of the part's size. At most
 * 60 for a hull that is not a prism- or pyramid-like polygon about an axis
 * (then the dihedral or cyclic group of the polygon). Only the rotations
 * that the others found do not generate are checked vertex by vertex; the
 * rest are shown to pass the same check by an error bound or by measuring
 * their vertices against the generated permutation, so the result is the
 * exhaustive search's, and a body of revolution of n vertices costs about
 * n^2 cheap distance tests for the candidate pairs (a few ns each; 0.05 s
 * at 4000 vertices) instead of n^2 vertex lookups. On success *symmetry is
 * owned by the caller (pd_symmetry_free). PD_ERR_USAGE (a NULL argument),
 * PD_ERR_NOMEM. */
PD_API pd_status pd_symmetry_find(const pd_part *part, pd_symmetry **symmetry, pd_diag *diag);

PD_API void pd_symmetry_free(pd_symmetry *symmetry);

/* Groups the stable poses of res (computed for this part) into classes:
 * poses i and j are one class when a rotation of pd_symmetry_find maps pose
 * i's resting facet onto pose j's, corner onto corner, and their centre of
 * mass heights agree within PD_TOL_SYMMETRY_REL of the size. class_of (room
 * for res->nposes entries) receives each pose's class; classes are numbered
 * 0.. by decreasing QS probability summed over their members (sums within
 * PD_TOL_PROB_TIE_REL in order of first appearance in the pose table), as
 * the poses are. *nclasses receives their number. Returns PD_ERR_USAGE (a NULL argument,
 * a pose whose facet is not a facet of part's hull), PD_ERR_NOMEM. */
PD_API pd_status pd_pose_classes(const pd_part *part, const pd_static_result *res, int *class_of,
                                 int *nclasses, pd_diag *diag);

/* Drop counts summed over classes: a new result with nposes = nclasses,
 * count[c] the sum over the class's poses, p = count / n and the 95% Wilson
 * interval recomputed for the class (an interval is not the sum of its
 * members'). n, unsettled, partial and the other run totals are copied;
 * trials is NULL. A PD_INITIAL_STATIONARY result whose p is the chain's
 * long-run pi gets pi summed over each class and the class's own resampled
 * interval (the same redraws, summed before the percentiles are taken), and
 * its first_count and transitions summed over classes (row and column);
 * stationary_shift is then measured between the classes. class_of has
 * sim->nposes entries in [0, nclasses), and nclasses is at most
 * sim->nposes (PD_ERR_USAGE otherwise).
 * Free with pd_sim_result_free. PD_ERR_USAGE, PD_ERR_NOMEM. */
PD_API pd_status pd_sim_result_grouped(const pd_sim_result *sim, const int *class_of, int nclasses,
                                       pd_sim_result **grouped, pd_diag *diag);

#ifdef __cplusplus
}
#endif
#endif
