/* impact.h (private): one frictional collision between the part and the
 * fixed floor, at a single contact point (paper section 5.1, eqs. 6-15).
 *
 * Contact frame: z along the floor normal (up), x and y tangential. The floor
 * is immovable, so the collision matrix is K = (1/m) I - R~ J^-1 R~ (eq. 11
 * with body 2 fixed), and every velocity below is the part's contact-point
 * velocity. The relative velocity along the collision is u(p) = u0 + K p, a
 * function of the accumulated impulse p only.
 *
 * The law: Coulomb friction during the collision (sliding, eq. 14, integrated
 * in the accumulated normal impulse pz; sticking, eq. 15), and restitution by
 * Poisson's hypothesis (pz_end = (1 + e) pz_c) or Stronge's energetic one
 * (the normal impulse's work during restitution is e^2 times minus its work
 * during compression). The energetic law never adds kinetic energy; Poisson's
 * can with friction in 3-D (docs/readings.md, "The collision law").
 *
 * A multi-contact scheme can call pd_impact_solve per contact with that
 * contact's K and u0; K's off-contact coupling is its business. */
#ifndef PD_IMPACT_H
#define PD_IMPACT_H

#include "posedrop/status.h"
#include "posedrop/types.h"

typedef enum pd_impact_law {
    PD_IMPACT_POISSON,  /* pz_end = (1 + e) pz_c: the paper's law */
    PD_IMPACT_ENERGETIC /* Stronge: restitution work = -e^2 compression work */
} pd_impact_law;

/* What happened during the collision: the outputs and the diagnostics a
 * simulator counts. */
typedef struct pd_impact_result {
    pd_vec3 p;         /* total impulse on the part, contact frame (N s) */
    pd_vec3 u1;        /* post-impact contact velocity u0 + K p (m/s) */
    double pz_c;       /* normal impulse at maximum compression */
    double dke;        /* kinetic energy change, p . (u0 + u1) / 2 (J) */
    int stuck;         /* the tangential velocity reached zero */
    int stick_stable;  /* ...and friction could hold it (eq. 15): stayed stuck */
    int resumed;       /* ...friction could not: slid off along the diverging ray */
    double theta_e;    /* direction of that ray (rad, from x), when resumed */
    int energy_gain;   /* dke > PD_TOL_IMPACT_ENERGY_REL |p| |u0| */
    int nsteps;        /* integrator steps taken (0 without friction) */
} pd_impact_result;

/* Scratch memory of the sliding integrator. One per thread, allocated once:
 * pd_impact_solve allocates nothing. */
typedef struct pd_impact_work pd_impact_work;

/* NULL if memory runs out. */
pd_impact_work *pd_impact_work_alloc(void);
/* The same with the integrator's tolerance times tol_scale (in (0, 1]), for
 * tests of convergence. */
pd_impact_work *pd_impact_work_alloc_tol(double tol_scale);
/* Accepts NULL. */
void pd_impact_work_free(pd_impact_work *w);

/* K = inv_mass I - R~ Jinv R~ with R~ the skew matrix of r (contact point
 * minus centre of mass) and Jinv the inverse inertia tensor, all in the
 * contact frame. Symmetric positive definite whenever inv_mass > 0 and Jinv
 * is symmetric positive semi-definite. */
void pd_impact_K(double inv_mass, const double Jinv[3][3], pd_vec3 r, double K[3][3]);

/* The impulse of one collision.
 *   w    workspace; may be NULL when mu == 0 (no integration is needed then)
 *   K    collision matrix in the contact frame, symmetric positive definite
 *   u0   pre-impact contact velocity; u0.z < 0 approaches. A contact that is
 *        not approaching (u0.z >= 0) needs no impulse: p = 0, u1 = u0, PD_OK.
 *   mu   Coulomb friction coefficient, >= 0
 *   e    restitution coefficient in [0, 1]
 * Events are located to PD_TOL_IMPACT_EVENT_REL, so after a stable stick
 * |u1.x, u1.y| <= that times |u0|; with e = 0, |u1.z| <= that times |u0.z|.
 * Returns PD_OK; PD_ERR_NONFINITE (NaN or Inf in K or u0); PD_ERR_USAGE
 * (NULL out, w NULL with mu > 0, mu < 0, e outside [0, 1], K not symmetric
 * or not positive definite); PD_ERR_NO_CONVERGENCE (more than
 * PD_IMPACT_MAX_STEPS steps, or the integrator's step fell to round-off);
 * PD_ERR_INTERNAL (a non-finite result: a bug). On failure *out is left
 * untouched. */
pd_status pd_impact_solve(pd_impact_work *w, const double K[3][3], pd_vec3 u0, double mu, double e,
                          pd_impact_law law, pd_impact_result *out);

/* The direction theta (rad) of the diverging ray of eq. 14's tangential flow
 * at the origin: sliding along (cos theta, sin theta) keeps that direction
 * and speeds up. Exists when sticking is unstable; 0 and PD_OK if found,
 * PD_ERR_NO_CONVERGENCE if K and mu have no such ray. K is taken as is
 * (not normalised). Exposed for tests and for the simulator's diagnostics. */
pd_status pd_impact_diverging_ray(const double K[3][3], double mu, double *theta);

#endif
