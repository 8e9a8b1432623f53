/* part_check.h (private): what a call given a pd_part checks of it. */
#ifndef PD_PART_CHECK_H
#define PD_PART_CHECK_H

#include <stdint.h>
#include "posedrop/part.h"

/* PD_OK for a part as pd_part_build makes it (not NULL, with its mesh and a
 * hull of at least 4 facets, a positive size); PD_ERR_USAGE naming who
 * otherwise. */
pd_status pd_part_check(const pd_part *part, const char *who, pd_diag *diag);

/* A fingerprint of everything the static estimators and the drops read from
 * a part: its size, centre of mass, mass properties and hull (vertices,
 * facet loops, planes). Computed afresh on each call, so a part freed and
 * another built at the same address, or a part changed after its results
 * were computed, gives another value. */
uint64_t pd_part_fingerprint(const pd_part *part);

#endif
