/* design_match.h (private): poses of a changed part named by the poses of
 * the part as given (match.c). */
#ifndef PD_DESIGN_MATCH_H
#define PD_DESIGN_MATCH_H

#include "design/design_internal.h"

/* map[j] (res->nposes entries) receives the pose of bres whose facet
 * continues into pose j's facet of the changed part, or -1 (a pose the
 * part as given does not have). PD_ERR_NOMEM. */
pd_status design_pose_map(const pd_part *base, const pd_static_result *bres, const pd_part *part,
                          const pd_static_result *res, int *map);

/* The changed part's QS (which 0) or PQS (1) probability summed over the
 * poses map sends to base pose i. */
double design_pose_p(const pd_static_result *res, const int *map, int i, int which);

#endif
