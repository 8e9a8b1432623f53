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

#endif
