/* contact_phase.h (private): one vertex or one edge sliding on the floor,
 * integrated as a continuous motion instead of microcollisions (see
 * contact_phase.c for the model and when it hands back). */
#ifndef PD_CONTACT_PHASE_H
#define PD_CONTACT_PHASE_H

#include "posedrop/sim.h"
#include "settle/settle.h"
#include "base/gsl_adapter.h"
#include "contact/phase_forces.h"

/* The phase's integrators, one each per thread: the full motion's (13
 * unknowns) and a pivot's (2: two sticking contacts turning about their
 * edge, contact_pivot.h). NULL if out of memory. */
pd_ode *pd_contact_phase_ode_alloc(void);
pd_ode *pd_contact_pivot_ode_alloc(void);
/* The same with their tolerance times tol_scale (in (0, 1]), for tests of
 * convergence. */
pd_ode *pd_contact_phase_ode_alloc_tol(double tol_scale);
/* The full motion's integrator for a phase that starts spinning fast
 * (pd_contact_phase_spins_fast), the same tolerance times tol_scale; NULL
 * if out of memory. */
pd_ode *pd_contact_phase_spin_ode_alloc_tol(double tol_scale);
/* 1 if body b in state s turns faster than PD_PHASE_SPIN_FAST per
 * sqrt(L/g) under gravity g: its phase takes the spin integrator. */
int pd_contact_phase_spins_fast(const pd_body *b, double g, const pd_state *s);
pd_ode *pd_contact_pivot_ode_alloc_tol(double tol_scale);

/* 1 if state s, touching the floor at body vertices contacts[0..nc), is a
 * contact the phase can take: one or two contacts moving normally no faster
 * than the microcollisions' rest speed, each sliding or sticking, pressed by
 * positive forces, no other vertex down. Then s's constrained velocities are
 * zeroed (a sliding contact's normal one, a sticking contact's whole one),
 * without adding energy, for the phase to start from, and *phase is the
 * phase; otherwise s is left alone. settle gives the body, what resting
 * contact is, and the test that ends the drop. */
int pd_contact_phase_start(const pd_settle *settle, const pd_scene *scene, pd_state *s,
                           const int *contacts, int nc, pd_phase *phase);

/* Runs phase (from pd_contact_phase_start) from s for at most t_max
 * seconds, or until the energy test decides the drop; s becomes the state
 * where it ended and *t_used the time it took. Two sticking contacts turn
 * about their edge in closed form where pivot_ode is given
 * (pd_pivot_run; by pivot_ode where that declines), or by ode in full
 * where pivot_ode is NULL (the reference the reduced motion is tested
 * against). */
pd_status pd_contact_phase(const pd_settle *settle, pd_ode *ode, pd_ode *pivot_ode,
                           const pd_scene *scene, const pd_phase *phase, pd_state *s,
                           double t_max, double *t_used);

#endif
