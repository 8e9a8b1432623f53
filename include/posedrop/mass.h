/* posedrop/mass.h: volume, centre of mass and inertia of a closed mesh.
 *
 * Uniform density. Exact for the polyhedron (divergence theorem over each
 * triangle, Mirtich 1996 or the equivalent signed-tetrahedron form), evaluated
 * relative to a vertex of the part so that a part far from the origin loses no
 * digits to cancellation. */
#ifndef POSEDROP_MASS_H
#define POSEDROP_MASS_H

#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/mesh.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pd_mass {
    double volume;          /* m^3, positive */
    pd_vec3 com;            /* centre of mass, m, in the mesh's frame */
    double inertia[3][3];   /* inertia tensor about com per unit density, m^5 */
} pd_mass;

/* Mass properties of a closed, consistently oriented mesh (see pd_mesh_orient).
 * PD_ERR_COPLANAR if the volume is not positive beyond round-off. */
PD_API pd_status pd_mass_compute(const pd_mesh *mesh, pd_mass *mass, pd_diag *diag);

#ifdef __cplusplus
}
#endif
#endif
