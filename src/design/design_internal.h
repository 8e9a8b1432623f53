/* design_internal.h (private): what the design layer's files share.
 * change.c turns values of the changes into parts and gives each hull
 * vertex's and the centre of mass's motion along a change; match.c follows
 * facets from the part as given to a changed one; sensitivity.c and
 * design.c build on both. */
#ifndef PD_DESIGN_INTERNAL_H
#define PD_DESIGN_INTERNAL_H

#include "posedrop/design.h"

typedef struct design_ctx {
    const pd_part *base;
    const pd_change *changes;
    int n;
    pd_vec3 axes[3];
    pd_vec3 anchor;   /* the base part's centre of mass, file frame, m */
    pd_vec3 delta0;   /* its offset from the material's centre (0 unless given) */
    int uniform;      /* 1: the centre of mass follows the material */
    double lo[PD_DESIGN_MAX_CHANGES], hi[PD_DESIGN_MAX_CHANGES]; /* search
                         coordinates: log factor, or offset in m */
} design_ctx;

/* Checks the changes and fills ctx. PD_ERR_USAGE naming a bad change. */
pd_status design_ctx_init(design_ctx *ctx, const pd_part *base, const pd_change *changes, int n,
                          pd_diag *diag);

/* The value that leaves the part as it is: 1 for a factor, 0 for an offset. */
double design_identity(const pd_change *c);

/* The part at value (one per change). */
pd_status design_build(const design_ctx *ctx, const double *value, pd_part **out, pd_diag *diag);

/* The motion of every hull vertex of part (a changed part, or the base)
 * and of its centre of mass per unit of change k's value, into dv
 * (part->hull->nverts) and *dcom. */
void design_motion(const design_ctx *ctx, const pd_part *part, int k, pd_vec3 *dv,
                   pd_vec3 *dcom);

/* The facet of part's hull that continues facet f of the base's hull: the
 * one sharing most of its corners (mesh vertices), at least 3; -1 if none. */
int design_match_facet(const pd_part *base, int f, const pd_part *part, int *mark);

/* The base's facet whose outward normal is nearest n (unit), within
 * 5 degrees; -1 if none. */
int design_facet_by_normal(const pd_part *base, pd_vec3 n, double *angle);

#endif
