/* part_tol.h (private): the part model's acceptance test. Conventions as in
 * posedrop/tolerances.h. */
#ifndef PD_PART_TOL_H
#define PD_PART_TOL_H

#include "posedrop/tolerances.h"

/* The centre of mass must lie at least this far inside every hull facet
 * plane; closer is "on the hull" and the part is refused (it would balance on
 * a facet it touches with its own centre). Same bound as the plane tolerance:
 * the hull itself is only known to that accuracy. */
#define PD_TOL_COM_INSIDE_REL PD_TOL_PLANE_REL

#endif
