/* posedrop/part.h: the immutable part model.
 *
 * Built once from a mesh: welded, oriented, its mass properties and convex
 * hull computed and the centre of mass checked to lie strictly inside the
 * hull. Everything downstream (static estimators, drops) takes it const. */
#ifndef POSEDROP_PART_H
#define POSEDROP_PART_H

#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/hull.h"
#include "posedrop/mass.h"
#include "posedrop/mesh.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct pd_part_options {
    int com_given;  /* 1: use com below instead of the mesh's own centre of mass */
    pd_vec3 com;    /* metres, in the mesh's frame; read only when com_given */
    pd_cancel_flag *cancel; /* may be NULL (the default): see pd_part_build */
    /* May be NULL (the default): called from the calling thread as each
     * stage of the build starts ("welding", "convex hull", "orienting",
     * "mass properties", "self-crossing check"), for a progress line. */
    void (*stage)(void *user, const char *name);
    void *stage_user;
} pd_part_options;

PD_API void pd_part_options_default(pd_part_options *options);

/* The part's frame is the mesh's frame moved to origin, a point near the
 * part: every position below (mesh vertices, hull, centre of mass, mass
 * properties) is relative to it, so that its round-off is relative to the
 * part's size, not to its distance from the mesh's origin (a 1 um part at
 * 1000 km would otherwise carry rounding steps of 1e-4 of its size into every
 * height). Add origin to a position to get it in the mesh's frame.
 * Directions, areas and heights are the same in both. */
typedef struct pd_part {
    pd_vec3 origin;    /* m, in the mesh's frame; 0 for a part within about
                          its own size of the mesh's origin */
    pd_mesh *mesh;     /* welded and, when closed, consistently oriented */
    double size;       /* bounding-box diagonal, m: the length scale of all tolerances */
    int closed;        /* 1 if the mesh is a closed surface */
    int mass_known;    /* 1 if mass holds the mesh's own mass properties */
    pd_mass mass;      /* volume and inertia valid only when mass_known */
    pd_vec3 com;       /* centre of mass used: given or computed, m,
                          relative to origin */
    pd_hull *hull;
} pd_part;

/* Builds a part from a mesh (the mesh is copied, not kept). Steps: move to
 * the part's origin (above); weld at
 * PD_TOL_WELD_REL of the size; orient (faces flipped are reported by a warning);
 * mass properties; convex hull; centre of mass strictly inside the hull.
 * PD_ERR_CANCELLED when options->cancel is found set (non-zero, by another
 * thread or a signal handler): read between the stages of the build and
 * every few thousand steps of the weld, the orientation, the convex hull
 * and the self-crossing check.
 * A mesh that is not closed is accepted only with options->com_given.
 * options may be NULL. A mesh with a negative count or missing arrays, or
 * options with com_given other than 0 or 1, is PD_ERR_USAGE; a vertex index
 * out of range PD_ERR_RANGE; a non-finite coordinate or given centre of
 * mass PD_ERR_NONFINITE. A closed mesh whose mass properties are no solid's
 * (second moments negative, volume or moments beyond the convex hull's: a
 * surface through itself, shells that overlap or cancel) is
 * PD_ERR_ORIENTATION, and one too thin for its moments to be resolved (a rod
 * of radius below 1.3e-5 of its length) PD_ERR_COLLINEAR, unless
 * options->com_given: then the mesh's mass properties are not used (a
 * warning; mass_known 0) and the drops take the hull's inertia about the
 * given centre. Returns the statuses of pd_mesh_orient, pd_mass_compute
 * and pd_hull_build, PD_ERR_COM_OUTSIDE, PD_ERR_NOMEM; PD_ERR_RANGE for a
 * size outside 1e-30 to 1e30 m, where products of the part's lengths would
 * leave the normal doubles (docs/limits.md). */
PD_API pd_status pd_part_build(const pd_mesh *mesh, const pd_part_options *options,
                               pd_part **part, pd_diag *diag);

/* As pd_part_build, but the part takes *mesh over instead of copying it
 * (the copy is the size of the mesh again: 48 MB at 2 million triangles):
 * *mesh is set NULL and the mesh is the part's or freed, whatever the
 * outcome. For a caller that has no use for the mesh once the part is
 * built, as the command line has none for the file's. */
PD_API pd_status pd_part_build_take(pd_mesh **mesh, const pd_part_options *options,
                                    pd_part **part, pd_diag *diag);

PD_API void pd_part_free(pd_part *part);

#ifdef __cplusplus
}
#endif
#endif
