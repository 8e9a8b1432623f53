/* body.h (private): the rigid-body model of a part for dynamics, and the state
 * of one drop.
 *
 * Built once from a const pd_part and then shared, const, by every drop. The
 * body frame is the principal frame: origin at the centre of mass, axes along
 * the principal axes of inertia with moments ascending, so the inertia tensor
 * is diagonal and Euler's equations take their simplest form.
 *
 * Density is taken as 1 kg/m^3, so mass = volume. Pose statistics do not
 * depend on it: a uniform density rho scales mass and inertia alike, so every
 * impulse (eq. 11 of the paper: K is 1/m and J^-1 terms) scales by rho and
 * every velocity change, hence every trajectory, is unchanged. */
#ifndef PD_BODY_H
#define PD_BODY_H

#include "posedrop/diag.h"
#include "posedrop/part.h"
#include "posedrop/status.h"
#include "posedrop/types.h"
#include "base/mat3.h"
#include "base/quat.h"


typedef struct pd_body {
    double mass;          /* kg, at density 1 kg/m^3: the volume, m^3 */
    double moment[3];     /* principal moments about the com, ascending, kg m^2;
                             equal within PD_TOL_INERTIA_SYM_REL made exactly equal */
    double inv_moment[3]; /* 1 / moment */
    pd_quat frame;        /* principal frame -> part (mesh) frame rotation */
    pd_vec3 com;          /* centre of mass in the part frame, m */
    double size;          /* the part's size L (bounding-box diagonal), m */
    double rmax;          /* largest distance of a hull vertex from the com, m */
    double euler[3];      /* (I_j - I_k) / I_i: torque-free, dw_i/dt = euler[i] w_j w_k */
    double spin_accel;    /* |dw/dt| <= spin_accel |w|^2 in torque-free motion */
    int nverts;
    pd_vec3 *verts;       /* hull vertices, principal frame, relative to the com */
    int *adj_start;       /* nverts + 1 entries; edge neighbours of vertex i are */
    int *adj;             /*   adj[adj_start[i] .. adj_start[i+1]) */
    int *vf_start;        /* nverts + 1 entries; the facets around vertex i are */
    int *vf;              /*   vf[vf_start[i] .. vf_start[i+1]) */
    unsigned char *polish; /* 1: a corner of a facet around vertex i may lie
                              lower than i in a direction no edge neighbour
                              of i does (pd_body_support) */
    const int *facet_start; /* the hull's facet loops (borrowed: the body must */
    const int *facet_vert;  /*   not outlive its part) */
} pd_body;

/* The state of a dropping part. */
typedef struct pd_state {
    pd_vec3 x;  /* centre of mass, world frame, m */
    pd_quat q;  /* orientation: principal (body) frame -> world, unit */
    pd_vec3 v;  /* velocity of the centre of mass, world frame, m/s */
    pd_vec3 w;  /* angular velocity, body frame, rad/s */
} pd_state;

/* Builds the body of a part. Mass properties come from the part's mesh; if the
 * part's centre of mass was given (pd_part_options.com_given) the inertia is
 * moved to it by the parallel-axis theorem; if the mesh has no mass properties
 * (open mesh) the solid convex hull, about the given centre, stands in.
 * PD_ERR_USAGE (NULL), PD_ERR_COPLANAR (a moment not positive), PD_ERR_NOMEM.
 * On success *body is owned by the caller (pd_body_free). */
pd_status pd_body_build(const pd_part *part, pd_body **body, pd_diag *diag);

void pd_body_free(pd_body *body);

/* The hull vertex minimising dot(dir, vertex) (dir in the body frame): for
 * dir = world up expressed in the body frame, the lowest vertex. Hill-climbs
 * the vertex graph from vertex start (any valid index; pass the last answer
 * for O(1) work on a slowly turning body), then checks the other corners of
 * the facets around the minimum, since merged facets are planar only to
 * PD_TOL_PLANE_REL; where they are flat to PD_TOL_SUPPORT_FLAT_REL that check
 * cannot change the answer and is skipped (polish[]). */
int pd_body_support(const pd_body *b, pd_vec3 dir, int start);

/* The same by scanning every vertex: the reference for tests and debug checks. */
int pd_body_support_scan(const pd_body *b, pd_vec3 dir);

/* Kinetic energy of state s, J (at density 1 kg/m^3). */
static inline double pd_body_kinetic(const pd_body *b, const pd_state *s)
{
    return 0.5 * b->mass * v3_dot(s->v, s->v) +
           0.5 * (b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                  b->moment[2] * s->w.z * s->w.z);
}

/* The body-frame inverse inertia applied to a: diag(1 / moment) a. */
static inline pd_vec3 pd_body_inv_inertia(const pd_body *b, pd_vec3 a)
{
    return v3(a.x * b->inv_moment[0], a.y * b->inv_moment[1], a.z * b->inv_moment[2]);
}

/* World coordinates of body vertex i in state s. */
static inline pd_vec3 pd_body_vertex_world(const pd_body *b, const pd_state *s, int i)
{
    return v3_add(s->x, quat_rotate(s->q, b->verts[i]));
}

#endif
