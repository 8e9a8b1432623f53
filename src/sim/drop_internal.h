/* drop_internal.h (private): what drop.c (the impulse simulator) and
 * drop_step.c (the stepping engines) share: the run's model and a thread's
 * work area. */
#ifndef PD_DROP_INTERNAL_H
#define PD_DROP_INTERNAL_H

#include "settle/basin.h"
#include "settle/descent_map.h"
#include "sim/drop.h"
#include "engines/engine.h"
#include "base/gsl_adapter.h"
#include "impact/impact.h"
#include "static/static_internal.h"

/* Contacts considered at once, and resolution rounds per impact. A face of
 * more corners than PD_MAX_CONTACTS touching at once is resolved through the
 * lowest PD_MAX_CONTACTS of them, which the rounds then correct. */
enum { PD_MAX_CONTACTS = 64, PD_MAX_ROUNDS = 64 };

struct pd_sim_model {
    pd_body *body;
    const pd_hull *hull;        /* the part's hull, part frame */
    pd_vec3 com;                /* part frame */
    pd_static_result *descent;  /* the exact quasi-static rest[] of every facet */
    double *barrier;            /* per facet: its basin's barrier height, m */
    double barrier_max;         /* the largest of them */
    struct pd_flat_facet *flat; /* per facet: what lying flat on it takes (flat_rest.h) */
    double flat_height;         /* m: with the centre of mass this high, flat on none */
    pd_star star;
    pd_descent_map map;         /* the decision test's descent, looked up */
    int *pose_of;               /* facet -> pose index in the caller's table, or -1 */
    const pd_static_result *poses;
    const pd_engine *engine;    /* NULL: the impulse simulator */
    double dt;                  /* the stepping engine's fixed step */
    double v_eps;               /* approach speeds below this are contact, not impact */
    double rest_fall;           /* m: how far resting contact falls between microcollisions */
    double v_rest;              /* approach speeds up to this are resting contact (e = 0) */
};

struct pd_drop_work {
    pd_impact_work *impact;
    pd_ode *phase;              /* the sliding phases' integrator */
    pd_ode *pivot;              /* and the pivots' (contact_pivot.h) */
    pd_engine_world *world;     /* the stepping engine's, or NULL */
    const pd_engine *engine;
    int contacts[PD_MAX_CONTACTS];
};

#endif
