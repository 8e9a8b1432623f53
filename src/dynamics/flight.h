/* flight.h (private): a part's motion between collisions, and the time of its
 * next impact with the floor z = 0.
 *
 * A flight is planned once from its initial state (the invariants of the
 * torque-free motion, the elliptic modulus and phase) and then evaluated at
 * any time in closed form, at a cost independent of the time: no step size,
 * no accumulated integration error, no allocation. */
#ifndef PD_FLIGHT_H
#define PD_FLIGHT_H

#include "dynamics/body.h"
#include "dynamics/flight_theta.h"
#include "posedrop/status.h"

typedef enum pd_flight_kind {
    PD_FLIGHT_STILL,    /* no rotation */
    PD_FLIGHT_AXIAL,    /* spherical or symmetric top, or a steady spin about a
                           principal axis: two uniform rotations */
    PD_FLIGHT_ELLIPTIC, /* asymmetric top: Jacobi elliptic functions */
    PD_FLIGHT_BOUNDS    /* an asymmetric top of which only the bounds are planned
                           (pd_flight_plan_bounds): evaluable at t = 0 alone
                           until pd_flight_complete */
} pd_flight_kind;

typedef struct pd_flight {
    pd_state s0;
    double g;            /* gravity, m/s^2, along -z */
    pd_flight_kind kind;
    double lambda;       /* |angular momentum| per unit density... i.e. |L|, kg m^2/s */
    double wmax;         /* bound on |angular velocity| over the flight, rad/s */
    pd_vec3 lhat;        /* L / |L|, world frame */
    /* AXIAL: q(t) = rot(lhat, a t) q0 rot(axis, b t) */
    double a, b;
    pd_vec3 axis;        /* body frame */
    double J0[3];        /* inverse principal moments (body order) */
    /* ELLIPTIC: see flight.c for the derivation */
    int perm[3];         /* chart axis i is body axis perm[i] ... */
    double sgn[3];       /* ... times sgn[i] */
    pd_quat e;           /* body -> chart rotation ... */
    int e_kind;          /* ... 0 identity, 1 half turn about x, 2 quarter turn about y */
    double wsc[3];       /* body rate component perm[i] = wsc[i] u[i] (sgn lambda J) */
    pd_quat Q0;          /* the angular-momentum frame: L-frame -> world */
    double J[3];         /* inverse moments in chart order */
    double alpha[3];     /* amplitudes of u = L/|L| in the chart: cn, sn, dn */
    double m, k, n;      /* parameter, modulus, characteristic */
    double Omega;        /* d tau / dt */
    int theta;           /* 1: by theta series (th, rate), else by Legendre's
                            integrals (tau0, K2, Pc, P0) */
    double tau0;         /* elliptic argument tau(t) = tau0 + Omega t */
    double K2;           /* the period 2K of dn (0 on the separatrix: no period) */
    double Pc;           /* complete integral of the third kind */
    double P0;           /* P(am tau0) with periods unrolled */
    double rate;         /* phi(t) = rate t + arg Y(v) - arg Y(v0) (flight_theta.h) */
    pd_theta th;         /* last: pd_flight_plan zeroes only what precedes it */
} pd_flight;

/* pd_flight_plan (below) in two halves, the same flight bit for bit. The
 * first plans all but an asymmetric top's rotation (s0, g, lambda, wmax,
 * lhat, and the axial cases whole); an asymmetric top is then of kind
 * PD_FLIGHT_BOUNDS, which pd_flight_eval evaluates at t = 0 only. The second
 * solves that rotation (the elliptic plan, most of a plan's cost) and does
 * nothing for a flight already complete. A drop plans after every collision,
 * but a contact still touching afterwards leads straight to the next
 * collision, and then the rotation was never needed: about a third of a
 * box's plans (docs/performance.md). Statuses as pd_flight_plan's; after a
 * failed pd_flight_complete the flight stays of kind PD_FLIGHT_BOUNDS. */
pd_status pd_flight_plan_bounds(const pd_body *b, const pd_state *s0, double g, pd_flight *f);
pd_status pd_flight_complete(const pd_body *b, pd_flight *f);

/* Plans the flight of body b from state s0 under gravity g (m/s^2, >= 0).
 * PD_ERR_USAGE (NULL, g < 0), PD_ERR_NONFINITE (a non-finite state, or an
 * elliptic phase that overflows away from the middle axis). On failure *f
 * may be partly written (it is planned in place): it holds no flight and
 * must not be evaluated. */
static inline pd_status pd_flight_plan(const pd_body *b, const pd_state *s0, double g,
                                       pd_flight *f)
{
    pd_status st = pd_flight_plan_bounds(b, s0, g, f);
    return st != PD_OK ? st : pd_flight_complete(b, f);
}

/* The state at time t (s, may be negative) after the start. The com is
 * exactly ballistic; the rotation is the closed-form torque-free motion.
 * PD_ERR_NONFINITE if an elliptic function fails (cannot happen for a planned
 * flight and finite t). */
pd_status pd_flight_eval(const pd_flight *f, double t, pd_state *out);
/* (PD_ERR_USAGE at t != 0 for a flight of kind PD_FLIGHT_BOUNDS.) */

/* Plan and evaluate in one: advances *s by dt. */
pd_status pd_flight_advance(const pd_body *b, pd_state *s, double g, double dt);

typedef enum pd_impact_kind {
    PD_IMPACT_NONE, /* no contact in (0, t_max] */
    PD_IMPACT_AT,   /* first contact at time t > 0 */
    PD_IMPACT_NOW   /* already touching at t = 0 (within PD_TOL_IMPACT_REL) */
} pd_impact_kind;

typedef struct pd_impact {
    pd_impact_kind kind;
    double t;       /* time of contact, s (t_max for NONE) */
    int vertex;     /* lowest hull vertex at t (body index) */
    double height;  /* its height above the floor at t, m, in [-tol, tol] on contact */
    int ncontacts;  /* vertices in contact at t (pd_flight_impact);
                       may exceed the capacity given, then only that many are listed */
    int steps;      /* conservative-advancement steps taken */
} pd_impact;

/* First time in (0, t_max] at which the lowest hull vertex reaches the floor,
 * to within PD_TOL_IMPACT_REL * L, never after the true first contact (a
 * contact that dips below the floor by more than the tolerance between
 * samples cannot be stepped over: see flight.c). contacts (capacity ncap, may
 * be NULL with ncap 0) receives the touching vertices, the lowest first:
 * those within PD_TOL_CONTACT_REL * L of the floor and, with window > 0 (s),
 * those that would reach it within window at their present velocity.
 * PD_ERR_USAGE, PD_ERR_NO_CONVERGENCE (PD_CONTACT_MAX_STEPS), PD_ERR_NONFINITE. */
pd_status pd_flight_impact(const pd_body *b, pd_flight *f, double t_max, double window,
                           int *contacts, int ncap, pd_impact *out);

/* The same from time t0 of the flight on, at its state there (as
 * pd_flight_eval gives it): the first contact in (t0, t_max], or
 * PD_IMPACT_NOW if touching at t0; times are the flight's own (from its
 * plan). A flight stays valid until its next contact, so a caller that has
 * moved the state along it need not plan it again. The search for the lowest
 * vertex starts from vertex start (any index; one near the lowest at t0
 * saves the climb to it, pd_flight_impact starts from 0). Both complete a
 * flight planned by its bounds alone (pd_flight_complete) before they
 * evaluate it, and only then: touching at t0 needs no rotation. */
pd_status pd_flight_impact_from(const pd_body *b, pd_flight *f, double t0, const pd_state *at,
                                int start, double t_max, double window, int *contacts, int ncap,
                                pd_impact *out);

/* The per-vertex step of the impact search (flight_impact.c) from state s, all
 * vertices above the floor: the smallest positive root D over the hull's
 * vertices v of z_v + z_v' D - B D^2 / 2 (z_v, z_v': v's height and its rate
 * in s; B >= 0 a bound on -z_v''), HUGE_VAL if none has one. Hill-climbs from
 * vertex start (any; the lowest is a good one). For the impact search and its
 * tests. */
double pd_flight_vertex_step(const pd_body *b, const pd_state *s, double B, int start);

/* The impact search's curvature step (flight_impact.c) from state s, all
 * vertices above the floor: the smallest root D in (0, H] over the hull's
 * vertices v of z_v + z_v' D - (B0 - b_v . c) D^2 / 2, or H if none is
 * smaller, where c is the second derivative of world up in the body frame and
 * B0 = max(g + C H / 3, |c| rmax), C bounding every vertex's third derivative
 * while |w| <= wmax: a time the part cannot reach the floor before. For the
 * impact search and its tests. */
double pd_flight_curvature_step(const pd_body *b, const pd_state *s, double g, double wmax,
                                double H, int start);

#endif
