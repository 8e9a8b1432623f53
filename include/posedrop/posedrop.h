/* posedrop/posedrop.h: the whole public API of libposedrop (and of
 * libposedrop-bullet, posedrop/bullet.h).
 *
 * Typical use:
 *   pd_mesh *mesh; pd_part *part; pd_static_result *res; pd_diag diag;
 *   pd_diag_init(&diag);
 *   pd_mesh_read("cap.stl", NULL, &mesh, &diag);
 *   pd_part_build(mesh, NULL, &part, &diag);
 *   pd_static_estimate(part, NULL, &res, &diag);
 *   ... res->poses[i].p_qs, res->poses[i].p_pqs ...
 *   pd_sim_run(part, res, NULL, NULL, &sim, &diag);   (2000 drops, the paper's scene)
 *   ... sim->p[i], sim->ci_lo[i], sim->ci_hi[i] ...
 * each call returning a pd_status to check (PD_OK == 0). */
#ifndef POSEDROP_POSEDROP_H
#define POSEDROP_POSEDROP_H

#include "posedrop/bullet.h"
#include "posedrop/design.h"
#include "posedrop/diag.h"
#include "posedrop/fit.h"
#include "posedrop/hull.h"
#include "posedrop/mass.h"
#include "posedrop/mesh.h"
#include "posedrop/part.h"
#include "posedrop/sensitivity.h"
#include "posedrop/sim.h"
#include "posedrop/static.h"
#include "posedrop/status.h"
#include "posedrop/symmetry.h"
#include "posedrop/tolerances.h"
#include "posedrop/types.h"
#include "posedrop/version.h"

#endif
