/* compliant.h (private): a compliant impact of a part on the floor, with as
 * many contacts as touch while it lasts, and the lasting face contact it may
 * turn into.
 *
 * Every hull vertex below the floor pushes by the normal law of
 * compliant_law.h, with a stiffness set when it touches from its own
 * effective mass (k = m_c omega^2, m_c the inverse of the normal entry of the
 * contact's inverse mass: alone, it would bounce with the scene's e and last
 * T) and a damping from its own approach speed. Each contact that pushes
 * also resists sliding by Coulomb friction, sticking or sliding, found as
 * the tangential impulse of each step that stops the contact's sliding
 * within the cone mu times its normal impulse (the contacts coupled through
 * the body, solved by Gauss-Seidel sweeps). Vertices that reach the floor
 * while the impact lasts join it.
 *
 * The motion is stepped by semi-implicit (symplectic) Euler in the body frame,
 * the step set by the law's rebound error (pd_compliant_law_step) and
 * shortened for several contacts.
 * The run ends when
 *   - no vertex is below the floor and none will reach it within two steps
 *     (SEPARATED: flight again);
 *   - at most two contacts are below the floor, none has touched for a
 *     contact duration and both rest: they move either way no faster than
 *     resting contact arrives and carry a few times the part's weight at
 *     most, so no bounce is under way (QUIET: one vertex or an edge resting,
 *     which the exact contact phases take over; the part is lifted onto the
 *     floor, by its static compression, about g / omega^2);
 *   - the outcome is decided (pd_settle_outcome on the state with its
 *     elastic energy counted as height) (DECIDED);
 *   - the time runs out (TIME), or the run is cancelled (CANCELLED). */
#ifndef PD_COMPLIANT_H
#define PD_COMPLIANT_H

#include "contact/compliant_law.h"
#include "dynamics/body.h"
#include "posedrop/sim.h"
#include "settle/settle.h"

typedef struct pd_compliant {
    pd_compliant_law law;
    double h1;          /* s: the step with one contact (h1 / sqrt(n) with n) */
    double band;        /* m: vertices this close to the floor are watched */
    double sweep_tol;   /* friction sweeps stop when no impulse moves more
                           than this times mu times its normal impulse */
} pd_compliant;

typedef enum pd_compliant_end {
    PD_COMPLIANT_SEPARATED,
    PD_COMPLIANT_QUIET,
    PD_COMPLIANT_DECIDED,
    PD_COMPLIANT_TIME,
    PD_COMPLIANT_CANCELLED  /* the flag given to pd_compliant_work_watch was set */
} pd_compliant_end;

typedef struct pd_compliant_result {
    pd_compliant_end end;
    int pose;           /* DECIDED: the pose index */
    double time;        /* s the run lasted */
    double rest_depth;  /* m: the deepest any vertex went below the floor
                           while every contact rests (as QUIET has it: slow,
                           lightly loaded), not a bounce's elastic compression */
    long steps;
    int energy_gain;    /* 1: the energy rose across the run and was scaled back */
} pd_compliant_result;

typedef struct pd_compliant_work pd_compliant_work;

/* The model for restitution e, contact duration T > 0 (s) and the body b.
 * tol_scale (1 for the model as defined, below 1 to tighten) scales every
 * numerical tolerance of the run: the step and the friction sweeps' stop.
 * PD_ERR_RANGE, PD_ERR_NO_CONVERGENCE, PD_ERR_NOMEM. */
pd_status pd_compliant_init(double e, double T, const pd_body *b, double tol_scale,
                            pd_compliant *c);

/* The model for a law already made (pd_compliant_law_init or a table's). */
void pd_compliant_from_law(const pd_compliant_law *law, const pd_body *b, double tol_scale,
                           pd_compliant *c);

pd_compliant_work *pd_compliant_work_alloc(const pd_body *b);
void pd_compliant_work_free(pd_compliant_work *w);

/* The run's cancel flag (may be NULL): pd_compliant_run reads it at every
 * step and stops (CANCELLED) once it is set, so that a long run does not
 * hold up a cancelled batch of drops. */
void pd_compliant_work_watch(pd_compliant_work *w, const pd_cancel_flag *cancel);

/* Runs the impact of the part in state s (a vertex on the floor, within the
 * contact tolerance, at least one approaching) for at most t_max seconds;
 * s is left at the run's end. PD_ERR_NONFINITE if the motion stops being
 * finite. */
pd_status pd_compliant_run(const pd_compliant *c, pd_compliant_work *w, const pd_settle *settle,
                           const pd_scene *scene, pd_state *s, double t_max,
                           pd_compliant_result *r);

/* One step's friction, as a run solves it, exposed for tests: n pushing
 * contacts (n at most the body's vertex count) at r[j] (body frame, from
 * the centre of mass) with normal impulses pn[j] (N s), the world's x and y
 * axes ex, ey in the body frame, friction mu. v (world frame) and wv (body
 * frame) are changed by the friction impulses, which are written to p (x
 * and y per contact, 2n). pair 1 solves two contacts that can both stick in
 * closed form once a sweep leaves both within their cones, or
 * PD_COMPLIANT_PAIR_AFTER sweeps, have not converged them (as a run does),
 * pair 2 tries that first, pair 0 never; else
 * Gauss-Seidel sweeps, at most sweeps of
 * them, stopped when no impulse moves by tol times mu times the largest
 * normal impulse (a run: PD_COMPLIANT_SWEEPS, the model's sweep_tol).
 * Returns the sweeps made, 0 for the closed form, -1 if the cap stopped
 * them. */
int pd_compliant_friction(pd_compliant_work *w, const pd_body *b, int n, const pd_vec3 *r,
                          const double *pn, pd_vec3 ex, pd_vec3 ey, double mu, double tol,
                          int sweeps, int pair, pd_vec3 *v, pd_vec3 *wv, double *p);

#endif
