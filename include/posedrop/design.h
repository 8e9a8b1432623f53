/* posedrop/design.h: which change to the part moves which pose, and a part
 * changed to meet a target.
 *
 * A change is a family of parts: the part stretched along one of its
 * principal axes (the whole of it, or only the slab between two planes
 * across the axis, the rest moved rigidly), or its centre of mass moved
 * along one (an insert or a hollow). The QS and PQS probabilities are sums
 * of spherical areas whose corners move smoothly with the part's vertices
 * and centre of mass, so their derivatives along a change are exact
 * (closed forms, while no facet changes stability and no PQS band changes
 * side); the drops' are central differences of paired drops (the same
 * seed on both sides: common random numbers) with 95% intervals.
 *
 * pd_design_run searches the changes' ranges for the part whose poses best
 * meet a goal: on QS or PQS first (Levenberg-Marquardt on their exact
 * Jacobian, from the best points of a coarse scan), then on drops of a
 * fixed seed (common random numbers: Broyden's update of the static
 * Jacobian for a target, GSL's Nelder-Mead simplex for a maximum), and
 * checks the result on fresh drops of another seed. docs/design.md gives
 * the method and the demonstrations. */
#ifndef POSEDROP_DESIGN_H
#define POSEDROP_DESIGN_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/part.h"
#include "posedrop/sim.h"
#include "posedrop/static.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* At most this many changes at once. */
#define PD_DESIGN_MAX_CHANGES 9

/* The part's principal axes (of its inertia about the centre of mass,
 * uniform density), named after the file's axes: axes[0] is the principal
 * axis nearest the file's x (the permutation of the three that keeps them
 * nearest), with a positive x component, and so on. When the file's own
 * axes are principal (an inertia tensor diagonal in them to 1e-9 of its
 * norm, which includes every tie: a cube, a solid of revolution about z)
 * they are the file's axes. A part whose mass properties are unknown
 * (mass_known 0) takes the file's axes. PD_ERR_USAGE for a NULL argument. */
PD_API pd_status pd_design_axes(const pd_part *part, pd_vec3 axes[3], pd_diag *diag);

typedef enum pd_change_kind {
    /* Stretch by a factor along a principal axis, about the centre of mass
     * (which a uniform part keeps): value 1 is the part as given. With
     * slab, only the part between the planes u = from and u = to across
     * the axis (u = axis . x, x in the file's frame, m) is stretched; what
     * lies beyond moves rigidly along the axis, the side holding the centre
     * of mass standing still. Exact for a slab whose planes meet the mesh
     * only at vertices (a flange's faces); vertices elsewhere move by the
     * same rule, the triangles between them staying flat. */
    PD_CHANGE_SCALE = 0,
    /* Move the centre of mass along a principal axis by value m (0 is the
     * part as given): the part's own offset from its material's centre, if
     * it was given one, plus this. */
    PD_CHANGE_COM
} pd_change_kind;

typedef struct pd_change {
    pd_change_kind kind;
    int axis;           /* 0, 1, 2: pd_design_axes' axes[axis] */
    int slab;           /* PD_CHANGE_SCALE: 1 stretches only from <= u <= to */
    double from, to;    /* m, from < to; slabs of one axis must not overlap */
    double lo, hi;      /* the range searched: factors (0 < lo < hi) or
                           offsets in m (lo < hi) */
} pd_change;

/* The part changed by value (one per change): a new part the caller frees.
 * Its mesh holds the base part's vertices, moved, in the same order.
 * PD_ERR_USAGE (a bad change or value: the message names it),
 * PD_ERR_COM_OUTSIDE (an offset that leaves the part), and what
 * pd_part_build returns; PD_ERR_RANGE when the change welds vertices
 * together (a factor that flattens the part to round-off). */
PD_API pd_status pd_design_apply(const pd_part *part, const pd_change *changes, int nchanges,
                                 const double *value, pd_part **changed, pd_diag *diag);

/* One pose (or class) and one change. */
typedef struct pd_design_sens_row {
    int pose;           /* 0-based pose of the static result, or class */
    int change;         /* 0-based index into the changes */
    double d_qs, d_pqs; /* exact derivatives per unit of the value (per unit
                           factor, or per m) at the part as given */
    int qs_kink, pqs_kink; /* 1 when the part sits on a boundary of the
                           QS (PQS) structure: the central difference over
                           1e-4 of a factor (of the size, for an offset)
                           disagrees with the derivative by more than 10%.
                           Then a step either way changes which facets are
                           stable, where one topples, or (PQS) which bands
                           move: a symmetric part's tied facets stop tying
                           when a change breaks the symmetry, and PQS jumps */
    double d_p, lo, hi; /* drops: (p(+step) - p(-step)) / (2 step) from
                           paired drops of one seed, and its 95% interval
                           (normal, from the per-drop paired differences);
                           0 when no drops were asked for */
} pd_design_sens_row;

typedef struct pd_design_sens {
    int nposes;         /* poses, or classes with class_of */
    int nchanges;
    double step[PD_DESIGN_MAX_CHANGES]; /* the drops' half step per change */
    long ndrops;        /* drops per side (0: none) */
    pd_design_sens_row *rows; /* nposes * nchanges, pose-major */
} pd_design_sens;

/* The sensitivities of part's poses (res: its pd_static_estimate under
 * options, NULL options the defaults; PD_PQS_BAND_EXACT is refused, its
 * band being a quadrature) to each change. class_of (res->nposes entries,
 * pd_pose_classes) groups poses into nclasses classes, or NULL. With
 * sim != NULL and sim->ndrops > 0, drops of scene (NULL: defaults) at each
 * change's value +- step (factor 1 +- 0.05, offset +- 0.02 of the part's
 * size) give d_p; each side's poses are matched to res's by their facets'
 * vertices. *out is the caller's (pd_design_sens_free).
 * PD_ERR_USAGE, PD_ERR_NOMEM, and what the drops return. */
PD_API pd_status pd_design_sensitivity(const pd_part *part, const pd_static_result *res,
                                       const pd_static_options *options,
                                       const pd_change *changes, int nchanges,
                                       const int *class_of, int nclasses, const pd_scene *scene,
                                       const pd_sim_options *sim, pd_design_sens **out,
                                       pd_diag *diag);

PD_API void pd_design_sens_free(pd_design_sens *sensitivity);

typedef enum pd_design_goal {
    PD_GOAL_TARGET = 0, /* each named pose at its probability: least squares */
    PD_GOAL_MAXIMISE,   /* the named poses' summed probability as high as can be */
    PD_GOAL_EQUALISE    /* the named poses equally likely: least squares of
                           each against their mean */
} pd_design_goal;

typedef enum pd_design_model { PD_DESIGN_QS = 0, PD_DESIGN_PQS } pd_design_model;

/* A pose named by the outward normal of its resting facet in the part's
 * (file's) frame, as posedrop prints it: the hull facet of the part as
 * given whose normal is nearest, within 5 degrees; followed through the
 * changes by its vertices. */
typedef struct pd_design_target {
    pd_vec3 normal;
    double p;           /* PD_GOAL_TARGET: the probability wanted, 0..1 */
} pd_design_target;

typedef struct pd_design_options {
    pd_static_options statics; /* pd_static_options_default */
    pd_design_model model;     /* which static estimate the first stage
                                  searches: PD_DESIGN_PQS */
    int group;                 /* 1: a target names its pose's class (the
                                  poses a rotation of the changed part maps
                                  onto it), summed; 0 */
    pd_scene scene;            /* the drops' scene: pd_scene_default */
    pd_sim_options sim;        /* the refinement's drops: ndrops per
                                  evaluation (0: no refinement), seed (the
                                  same at every evaluation), threads,
                                  engine; 20000 */
    int max_evals;             /* drop evaluations of the refinement, >= 1; 12 */
    long check_drops;          /* fresh drops of the result, 0: none; 20000 */
    uint64_t check_seed;       /* their seed, another than sim.seed's; 2 */
    /* Called after each stage's steps (stage "scan", "static", "drops",
     * "check"), may be NULL. */
    void (*progress)(void *user, const char *stage, int evals, double objective);
    void *progress_user;
} pd_design_options;

PD_API void pd_design_options_default(pd_design_options *options);

typedef struct pd_design_target_result {
    double p_target;           /* PD_GOAL_TARGET: the target; else the mean
                                  reached (equalise) or 1 (maximise) */
    double qs_before, pqs_before;  /* the part as given */
    double qs_static, pqs_static;  /* at the static stage's optimum */
    double qs_after, pqs_after;    /* at the result */
    double p_refine;           /* the refinement drops' estimate at the
                                  result (its seed), 0 without */
    double p_after, lo, hi;    /* fresh drops of the result, 95% Wilson */
    int vanished;              /* 1: the named facet is no resting pose of
                                  the result (it toppled, or merged into
                                  another facet) */
    int appeared;              /* 1: the named facet was no resting pose of
                                  the part as given */
    pd_vec3 normal_after;      /* the facet's normal on the result */
} pd_design_target_result;

typedef struct pd_design_result {
    int nchanges;
    double value_before[PD_DESIGN_MAX_CHANGES]; /* 1 or 0 (clamped into range) */
    double value_static[PD_DESIGN_MAX_CHANGES];  /* the static stage's optimum */
    double value[PD_DESIGN_MAX_CHANGES];         /* the result */
    int ntargets;
    pd_design_target_result *targets;
    double objective_static;   /* the static model's objective at its optimum */
    double objective_refine;   /* the refinement drops' at the result */
    double objective_after;    /* the fresh drops' */
    int static_evals;          /* static evaluations (each QS + PQS + Jacobian) */
    int drop_evals;            /* refinement evaluations */
    long drops;                /* drops in all, refinement and check */
    int poses_before, poses_after; /* stable poses of the part as given, of the result */
    pd_part *part;             /* the result, the caller's through
                                  pd_design_result_free */
    int partial;               /* 1: the drops were cancelled (options.sim's
                                  cancel flag): the result is the best point
                                  found before, not refined further and not
                                  checked (p_after, lo, hi 0) */
} pd_design_result;

/* Designs: searches changes (nchanges in 1..PD_DESIGN_MAX_CHANGES) for the
 * goal over targets (ntargets >= 1; PD_GOAL_EQUALISE >= 2), on part with
 * options (required; pd_design_options_default fills them). On success
 * *result is the caller's. PD_ERR_USAGE (a bad argument or a normal no
 * facet has: the message names it), PD_ERR_NOMEM, and what the drops
 * return. */
PD_API pd_status pd_design_run(const pd_part *part, const pd_change *changes, int nchanges,
                               pd_design_goal goal, const pd_design_target *targets,
                               int ntargets, const pd_design_options *options,
                               pd_design_result **result, pd_diag *diag);

PD_API void pd_design_result_free(pd_design_result *result);

#ifdef __cplusplus
}
#endif
#endif
