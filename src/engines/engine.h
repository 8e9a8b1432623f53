/* engine.h (private): the stepping engines that cross-check the impulse
 * simulator (ODE with libccd, Bullet).
 *
 * Each engine is one adapter file behind this C interface: a world holding
 * one dynamic body (the part's convex hull with its true mass, centre of mass
 * and principal inertia) and a static floor plane z = 0, stepped with a fixed
 * time step. The drop loop (drop_step.c) is shared: it sets the state the
 * impulse simulator would start from, steps, and decides rest by the same
 * energy barriers, so only the physics differs between engines.
 *
 * States are the impulse simulator's pd_state (body.h): com position and
 * velocity in the world, orientation principal frame -> world, angular
 * velocity in the principal (body) frame. */
#ifndef PD_ENGINE_H
#define PD_ENGINE_H

#include "dynamics/body.h"
#include "posedrop/hull.h"
#include "posedrop/sim.h"

typedef struct pd_engine_world pd_engine_world;

typedef struct pd_engine {
    const char *name;
    /* One world per thread. body: the part in principal axes (mass, moments,
     * hull vertices relative to the com); hull and body->frame give the
     * facets in the part frame if the engine wants planes. NULL on failure. */
    pd_engine_world *(*world_alloc)(const pd_body *body, const pd_hull *hull, const pd_scene *scene,
                                    double dt);
    void (*world_free)(pd_engine_world *w);
    /* Puts the body in state s (velocities included), resting contacts
     * cleared. */
    pd_status (*reset)(pd_engine_world *w, const pd_state *s);
    /* Advances one time step and reads the state back. PD_ERR_NONFINITE if
     * the engine produced a non-finite state. */
    pd_status (*step)(pd_engine_world *w, pd_state *s);
} pd_engine;

/* Restitution below this is taken as this by the contact law below, as by
 * the impulse simulator's compliant law (PD_COMPLIANT_E_MIN, in a layer this
 * one may not include): e = 0 needs an infinite damping ratio. */
#define PD_ENGINE_E_MIN 0.01

/* The spring-dashpot standing for one contact of the scene (contact_time
 * T > 0, restitution e), as natural frequency *omega (rad/s) and damping
 * ratio *zeta, for a contact of effective mass m: stiffness k = m omega^2,
 * damping c = 2 zeta m omega. The contact pushes only (the engines' contact
 * impulses are never negative), so it ends when the force k x + c x' falls
 * to zero, before the penetration does; for that law
 *     T = g(zeta) / omega,   e = exp(-zeta g(zeta)),
 *     g(zeta) = (pi - 2 asin zeta) / sqrt(1 - zeta^2)     (zeta < 1),
 *             = 2 acosh(zeta) / sqrt(zeta^2 - 1)          (zeta > 1), 2 at 1,
 * whatever the approach speed. zeta is found from e by bisection (e falls
 * from 1 at zeta = 0 toward 0), then omega from T. e is taken within
 * [PD_ENGINE_E_MIN, 1]. engine_contact.c; docs/engines-crosscheck.md derives
 * it. */
void pd_engine_contact_law(double T, double e, double *omega, double *zeta);

/* Steps a contact must span for an engine to stand for it by that law: with
 * a step h > T / PD_ENGINE_CONTACT_STEPS the engine keeps its own contact
 * (its bounce with restitution e), the law's own limit as T -> 0. Why 10:
 * both engines step the spring-dashpot implicitly, which loses about
 * e g^2 / 2 h / T of the rebound (g = omega T <= pi): at 10 steps a
 * corner's rebound of 0.3 comes out 0.25 (ODE) and 0.23 (Bullet), at 2
 * steps 0.18 and 0.10, at Bullet's default 1/960 s for T = 5e-4 s 0.02. A
 * contact that short is rigid as far as such a step can tell. */
#define PD_ENGINE_CONTACT_STEPS 10.0

extern const pd_engine pd_engine_ode;    /* engine_ode.c */
extern const pd_engine pd_engine_bullet; /* engine_bullet.cpp */

#endif
