/* phase_forces.h (private): the contact forces of a contact phase (see
 * contact_phase.c for the model), split from the phase's stepping so that
 * what is constant over a phase is computed once, at its start. */
#ifndef PD_PHASE_FORCES_H
#define PD_PHASE_FORCES_H

#include "dynamics/body.h"

/* PD_PHASE_CLIP: a lone contact that sticks (slips slower than a slide
 * starts) but whose sticking force lies just outside the friction cone,
 * where pd_phase_slide_from_rest finds no direction (its two candidate
 * directions merge as the excess vanishes, closer than its search
 * resolves), or turning too fast for the slide to be judged
 * (contact_phase.c): it starts to slip all the same. Its force is the sticking
 * force's pull clipped to the cone's edge, mu fn along the tangent the
 * sticking force pulls along, with fn holding the normal acceleration at
 * zero, so the force is continuous where it began and the contact slips
 * from rest at the rate the excess gives; the limit of the slide from rest
 * as the excess vanishes (contact_phase.c ends it where the sticking force
 * is back inside the cone or the slip has become a slide). */
enum { PD_PHASE_SLIDE, PD_PHASE_STICK, PD_PHASE_CLIP };

/* One phase's contacts and what its force solve needs. In the body frame a
 * contact's response to a force is a constant 3 x 3 matrix, and a sticking
 * contact constrains its whole acceleration, which the body axes span as
 * well as any other basis: so while every contact sticks, the solve is one
 * constant linear map, set up once. */
typedef struct {
    const pd_body *b;
    int nc;
    int v[2];          /* contact vertices */
    int mode[2];       /* PD_PHASE_SLIDE, PD_PHASE_STICK or (one contact)
                          PD_PHASE_CLIP */
    double mu, g;      /* SI */
    double drill[2];   /* a sticking contact of a phase that can spin about
                          the floor's normal (not a pivot): its drilling
                          friction's couple per unit normal force,
                          (2/3) mu a (m), signed as the spin at the phase's
                          start; 0: none (pd_phase_modes sets none) */
    int from_rest[2];  /* a sliding contact that started from rest: its
                          friction's direction is t0, not its slip's, until it
                          slips (pd_phase_slide_from_rest) */
    pd_vec3 t0[2];     /* ...that direction, world, unit, horizontal */
    double L, T;       /* units: length, time */
    pd_vec3 r[2];      /* contact vertices, body frame */
    double M[2][2][3][3]; /* M[i][j] f: acceleration of contact i by force f at j */
    int singular;      /* every contact sticks and the constant system is singular */
    double P[6][6];    /* every contact sticks: forces = P (minus free accelerations) */
    int mapped;        /* M, singular and P set (pd_phase_map) */
} pd_phase;

/* What the forces of a state give: the com's acceleration (world), wdot
 * (body), and per contact its normal force, its margin inside the friction
 * cone (sticking: mu fn - |ft|; sliding from rest or clipped: how far its
 * sticking force would lie outside the cone, |ft| - mu fn of the sticking
 * solution, which the slip from rest lasts while it is positive; sliding:
 * infinite) and its slip speed. */
typedef struct {
    pd_vec3 acc, wdot;
    double fn[2], cone[2], slip[2];
} pd_phase_forces;

/* The phase of contacts[0..nc) (1 or 2) of state s: each contact slides if
 * it slips faster than slip_start, else sticks; gravity g, friction mu.
 * pd_phase_modes sets the contacts and their modes alone, for a caller that
 * may refuse the phase on them or needs no force solve (a pivot,
 * contact_pivot.h); pd_phase_map then sets up the solves, which
 * pd_phase_forces_of and pd_phase_project_velocity need (they fail
 * without); pd_phase_init does both. */
void pd_phase_modes(pd_phase *p, const pd_body *b, double g, double mu, const pd_state *s,
                    const int *contacts, int nc, double slip_start);
void pd_phase_map(pd_phase *p);
void pd_phase_init(pd_phase *p, const pd_body *b, double g, double mu, const pd_state *s,
                   const int *contacts, int nc, double slip_start);

/* A single sticking contact whose force leaves the friction cone starts to
 * slide from rest, in a direction t0 in which it then accelerates: sliding
 * friction -mu fn t0 leaves the contact's tangential acceleration along +t0.
 * Sets contact 0 of p (mapped, one contact) sliding from rest along the
 * direction of that kind it accelerates fastest in, its slip's acceleration
 * along it into *accel (m/s^2), and returns 1; 0 (p unchanged) if there is
 * none (sticking holds, or no direction gives a positive normal force). */
int pd_phase_slide_from_rest(pd_phase *p, const pd_state *s, double *accel);

/* Both contacts of an edge, sticking (a pivot) where a force leaves the
 * friction cone, start to slide from rest: each along a direction in which
 * its slip then grows (as above), both found together. p need not be
 * mapped (a pivot's start sets up no solve). Sets p so, mapped for the
 * slide, the slower slip's acceleration into *accel, and returns 1; 0 (p
 * unchanged) if no such pair is found. */
int pd_phase_slide_edge_from_rest(pd_phase *p, const pd_state *s, double *accel);

/* An edge whose contact i sticks with its force outside the friction cone
 * while the other slides: contact i starts to slide from rest along a
 * direction in which its slip then grows (as above), the other's friction
 * along its slip. Sets p (mapped) so, contact i's slip acceleration into
 * *accel, and returns 1; 0 (p unchanged) if there is none. */
int pd_phase_slide_end_from_rest(pd_phase *p, const pd_state *s, int i, double *accel);

/* The forces of state s (SI). 0, or 1 where the model does not hold (a
 * sliding contact with no slip to give friction a direction, a singular
 * system). */
int pd_phase_forces_of(const pd_phase *p, const pd_state *s, pd_phase_forces *out);

/* The same by the general solve: every layout assembled and solved densely
 * on the contacts' own tangent axes, as a reference for the specialised one. */
int pd_phase_forces_general(const pd_phase *p, const pd_state *s, pd_phase_forces *out);

/* Brings the constrained velocity components of s to zero (a sliding
 * contact's normal speed, a sticking contact's whole velocity) by the
 * impulses that change the kinetic energy least. 0 if singular. */
int pd_phase_project_velocity(const pd_phase *p, pd_state *s);

#endif
