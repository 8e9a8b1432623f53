/* contact_pivot.h (private): a phase of two sticking contacts (see
 * contact_pivot.c) as a rotation about the fixed edge through them, one
 * degree of freedom instead of the phase's thirteen unknowns. */
#ifndef PD_CONTACT_PIVOT_H
#define PD_CONTACT_PIVOT_H

#include "dynamics/body.h"
#include "contact/phase_forces.h"

/* The rotation about the edge of a phase's two contacts from a state s0
 * (angle 0): the edge's fixed line, the centre's arm about it, and the
 * moment about it. World quantities unless said otherwise. */
typedef struct {
    const pd_phase *p;
    pd_vec3 p0;        /* contact 0: a point of the axis */
    pd_vec3 e, eb;     /* the edge's unit direction, contact 0 -> 1; body frame */
    double len;        /* the edge's length */
    pd_vec3 u_par;     /* the centre's arm from p0 at angle 0: along e, */
    pd_vec3 u_perp;    /*   across e, */
    pd_vec3 e_u;       /*   and e x u_perp, where the arm turns to at angle pi/2 */
    pd_quat q0;        /* s0's orientation */
    pd_vec3 Ieb, gyro; /* body frame: I eb and eb x I eb, for the torque */
    double Ie;         /* moment about the edge */
    double k_sin, k_cos; /* angular acceleration = k_sin sin a + k_cos cos a */
} pd_pivot;

/* The pivot of phase p (two sticking contacts) at state s0. 0 where it has
 * none: not two sticking contacts, or a degenerate edge. */
int pd_pivot_init(pd_pivot *pv, const pd_phase *p, const pd_state *s0);

/* The rate of turn about the edge that keeps s's angular momentum about
 * it: the velocity of the pivot nearest s's in the kinetic energy's
 * metric, so it never adds energy (the impulses at the contacts that stop
 * them and change the energy least). */
double pd_pivot_rate_of(const pd_pivot *pv, const pd_state *s);

/* The angular acceleration at angle a (rad/s^2): gravity's torque about the
 * edge over the moment about it (the contacts' forces act on the axis). */
double pd_pivot_accel(const pd_pivot *pv, double a);

/* The state at angle a turning at rate w (rad/s) and, with it, its forces
 * as pd_phase_forces_of gives them (contact velocities zero, the squeeze
 * along the edge zero); returns the angular acceleration, as
 * pd_pivot_accel, to the bit. */
double pd_pivot_state(const pd_pivot *pv, double a, double w, pd_state *s, pd_phase_forces *F);

/* The pivot from angle 0 turning at w0 (rad/s) in closed form (the energy
 * gives the rate at every angle, an elliptic integral the time): to lead
 * (s) before its first event (a contact's normal force or cone margin
 * reaching 0, another neighbour of the contacts reaching the floor), or to
 * t_max (s), whichever is sooner; the angle, rate and time there into *a,
 * *w and *t (0 where the event is within lead of the start). 0 where it
 * cannot (no turn to follow, a motion that turns back twice): the caller
 * integrates. */
int pd_pivot_run(const pd_pivot *pv, double w0, double t_max, double lead, double *a, double *w,
                 double *t);

#endif
