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
    /* Sets the floor contact's friction, restitution and contact time
     * (resolved, never PD_CONTACT_TIME_AUTO) from scene, as world_alloc
     * does: for drops that draw their own (scene ranges). */
    pd_status (*material)(pd_engine_world *w, const pd_scene *scene);
    /* Puts the body in state s (velocities included), resting contacts
     * cleared. */
    pd_status (*reset)(pd_engine_world *w, const pd_state *s);
    /* Advances one time step and reads the state back. PD_ERR_NONFINITE if
     * the engine produced a non-finite state. */
    pd_status (*step)(pd_engine_world *w, pd_state *s);
    /* NULL, or why the engine cannot stand for this part in this scene
     * (a sentence to follow "the <engine> engine cannot run this part: "),
     * decided before any drop. NULL itself: the engine takes any part. */
    const char *(*refuses)(const pd_body *body, const pd_hull *hull, const pd_scene *scene);
} pd_engine;

extern const pd_engine pd_engine_ode;    /* engine_ode.c */
/* engine_bullet.cpp, in libposedrop-bullet: libposedrop itself never refers
 * to it, it only holds what pd_bullet_register hands to pd_engine_register. */
extern const pd_engine pd_engine_bullet;

/* The stepping engine of that kind in this program: ODE always, Bullet once
 * registered; NULL for the impulse simulator and for an unregistered one. */
const pd_engine *pd_engine_get(pd_engine_kind kind);

#endif
