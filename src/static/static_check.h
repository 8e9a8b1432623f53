/* static_check.h (private): whether a static result belongs to a part. */
#ifndef PD_STATIC_CHECK_H
#define PD_STATIC_CHECK_H

#include "posedrop/static.h"

/* PD_OK when res was computed for part (pd_part_check passes, and
 * res->part_fingerprint is the part's own) and its tables fit the part's
 * hull: a facet record per hull facet, poses on distinct facets in range.
 * PD_ERR_USAGE naming who otherwise: indexing one part's hull by another's
 * pose table reads and writes past the ends of its arrays. */
pd_status pd_static_result_check(const pd_part *part, const pd_static_result *res,
                                 const char *who, pd_diag *diag);

#endif
