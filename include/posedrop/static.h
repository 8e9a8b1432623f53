/* posedrop/static.h: the quasi-static (QS) and perturbed quasi-static (PQS)
 * pose estimators (Goldberg, Mirtich et al., sections 3 and 4).
 *
 * QS: each hull facet starts with the solid angle it subtends at the centre of
 * mass over 4 pi (a uniformly random initial orientation); an unstable facet
 * (centre of mass projecting outside it or on its boundary) hands its
 * probability down the quasi-static graph (QSG) until a stable facet.
 * PQS: before propagating, each stable facet gives the probability of a band of
 * angular width epsilon along each of its edges to the facet across the edge,
 * when that facet is unstable or starts more probable. */
#ifndef POSEDROP_STATIC_H
#define POSEDROP_STATIC_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/export.h"
#include "posedrop/part.h"
#include "posedrop/status.h"
#include "posedrop/types.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum pd_topple_rule {
    /* Exact quasi-static motion: steepest descent of the centre of mass height
     * over gravity directions. From a facet whose projected centre is nearest
     * a vertex, the part pivots about that vertex and may land on a facet that
     * shares only the vertex. */
    PD_TOPPLE_DESCENT = 0,
    /* The paper's QSG between edge-adjacent facets: across the edge nearest the
     * projected centre; from a vertex region, across the edge at that vertex
     * beyond which the projection lies farthest (best aligned with descent). */
    PD_TOPPLE_EDGE
} pd_topple_rule;

typedef enum pd_pqs_compare {
    PD_PQS_COMPARE_RAW = 0, /* compare the facets' solid-angle probabilities */
    PD_PQS_COMPARE_QS       /* compare their propagated QS probabilities */
} pd_pqs_compare;

typedef enum pd_pqs_band {
    PD_PQS_BAND_RECT = 0,   /* the paper's |a| * epsilon, clipped to triangle T */
    PD_PQS_BAND_EXACT       /* exact spherical area of T within epsilon of arc a */
} pd_pqs_band;

typedef struct pd_static_options {
    pd_topple_rule topple;  /* default PD_TOPPLE_DESCENT */
    double epsilon;         /* PQS perturbation angle, radians; default 20 deg */
    pd_pqs_compare compare; /* default PD_PQS_COMPARE_RAW */
    pd_pqs_band band;       /* default PD_PQS_BAND_RECT */
    pd_cancel_flag *cancel; /* may be NULL (the default): when found set (read
                               between the estimators' stages),
                               pd_static_estimate returns PD_ERR_CANCELLED */
} pd_static_options;

PD_API void pd_static_options_default(pd_static_options *options);

/* Whether every field of options holds one of its values, epsilon from 0 to
 * pi / 2 (NaN is not): PD_OK or PD_ERR_USAGE naming the field.
 * pd_static_estimate calls it first. */
PD_API pd_status pd_static_options_check(const pd_static_options *options, pd_diag *diag);

/* Per hull facet (same index as in part->hull). */
typedef struct pd_facet_result {
    double solid_angle; /* sr, subtended at the centre of mass */
    double p_raw;       /* solid_angle / (4 pi) */
    double area;        /* m^2 */
    double height;      /* centre of mass above the floor when resting here, m */
    int stable;         /* 1 iff the centre of mass projects strictly inside,
                           or on the boundary with no lower facet across it */
    int knife;          /* 1 if it projects on the boundary (within tolerance)
                           and a facet across it is lower: then unstable */
    int next;           /* QSG successor (unstable facets), -1 for stable ones */
    int rest;           /* the stable facet this facet ends on (itself if stable) */
    double p_qs;        /* final QS probability (0 unless stable) */
    double p_pqs;       /* final PQS probability (0 unless stable) */
} pd_facet_result;

/* One stable pose. */
typedef struct pd_pose {
    int facet;          /* hull facet index */
    pd_vec3 normal;     /* outward unit normal of the resting facet: the
                           direction of gravity in the part's frame */
    double area, height, p_qs, p_pqs;
} pd_pose;

typedef struct pd_static_result {
    int nfacets;
    pd_facet_result *facets;
    int nposes;
    pd_pose *poses;     /* by descending p_qs; ties (PD_TOL_PROB_TIE_REL) by
                           normal, lexicographically ascending */
    int nknife;         /* facets with a knife edge (each also warned) */
    uint64_t part_fingerprint; /* the part it was computed from: a hash of its
                           size, centre of mass, mass properties and hull.
                           pd_sim_run and pd_pose_classes refuse a part whose
                           own differs (PD_ERR_USAGE): another part, or one
                           changed since, whose hull the pose table does not
                           index */
} pd_static_result;

/* Runs QS and PQS on a part. options may be NULL (defaults). On success
 * *result is owned by the caller (pd_static_result_free). Returns
 * PD_ERR_USAGE (a NULL argument, options pd_static_options_check refuses),
 * PD_ERR_NOMEM, PD_ERR_INTERNAL
 * (a QSG link that would raise the centre of mass: a bug). */
PD_API pd_status pd_static_estimate(const pd_part *part, const pd_static_options *options,
                                    pd_static_result **result, pd_diag *diag);

PD_API void pd_static_result_free(pd_static_result *result);

/* The rigid transform that sets the part resting on a pose: its facet on
 * the floor z = 0, facing down, the part above it. transform is a 4x4
 * homogeneous matrix, row-major (transform[4 r + c]), that maps a point of
 * the mesh in its file's frame, in metres (pd_part.origin added to the
 * part's own positions), to the floor's frame. Its rotation's rows are
 * x, y, z with z = -pose->normal, x = (-z_y, z_x, 0) normalised, or (1, 0, 0)
 * when that is shorter than PD_PRINT_ZERO (a horizontal facet: round-off in
 * an axis-aligned normal does not spin the frame), y = z x x: the convention
 * of trimesh.poses.compute_stable_poses. The translation is along z only
 * and puts the lowest hull vertex on z = 0; the centre of mass then stands
 * at pose->height. pose is one of a pd_static_result's for this part (its
 * facet and normal are used). Returns PD_ERR_USAGE (a NULL argument, a
 * normal that is not a unit vector within 1e-9), PD_ERR_NONFINITE (a normal
 * that is not finite) or PD_ERR_RANGE (a facet not of the part's hull),
 * leaving transform untouched. */
PD_API pd_status pd_pose_transform(const pd_part *part, const pd_pose *pose, double transform[16],
                                   pd_diag *diag);

/* Solid angle (sr) of triangle abc seen from the origin, by the atan2 form of
 * Van Oosterom and Strackee (1983): full relative precision for tiny and thin
 * triangles. Positive when dot(a, cross(b - a, c - a)) > 0, as for a hull
 * facet's loop seen from a point inside the hull; negative otherwise. */
PD_API double pd_solid_angle_triangle(pd_vec3 a, pd_vec3 b, pd_vec3 c);

#ifdef __cplusplus
}
#endif
#endif
