/* sim_model.h (private): what a run of drops is built on, whatever the
 * engine: the model, built once per run from the part and shared read-only
 * by all threads, a thread's work area (so the drop loops never allocate),
 * and the release that starts every engine's drop of the same index from the
 * same state, so engines can be compared drop by drop. */
#ifndef PD_SIM_MODEL_H
#define PD_SIM_MODEL_H

#include <stdint.h>
#include "base/gsl_adapter.h"
#include "base/rng.h"
#include "contact/compliant.h"
#include "dynamics/body.h"
#include "engines/engine.h"
#include "impact/impact.h"
#include "posedrop/sim.h"
#include "settle/settle.h"

/* Contacts considered at once, and resolution rounds per impact. A face of
 * more corners than PD_MAX_CONTACTS touching at once is resolved through the
 * lowest PD_MAX_CONTACTS of them, which the rounds then correct. */
enum { PD_MAX_CONTACTS = 64, PD_MAX_ROUNDS = 64 };

typedef struct pd_sim_model {
    pd_body *body;
    const pd_hull *hull;        /* the part's hull, part frame */
    pd_vec3 com;                /* part frame */
    const pd_static_result *poses;
    pd_settle settle;           /* when a drop is decided; resting contact */
    const pd_engine *engine;    /* NULL: the impulse simulator */
    double dt;                  /* the stepping engine's fixed step */
    double time_limit;          /* s: options->time_limit, or pd_time_limit_auto's */
    double top_time;            /* s: the longest the part can spin as a top on
                                   one vertex before drilling friction stops
                                   it (0: nothing drills); an automatic
                                   limit leaves that time out (drop.c) */
    double v_eps;               /* approach speeds below this are contact, not impact */
    double contact_time;        /* s: the scene's, PD_CONTACT_TIME_AUTO resolved */
    int compliant_on;           /* the impulse engine with contact_time > 0 */
    pd_compliant compliant;     /* its impacts with more than one contact */
    double tol_scale;           /* every integration tolerance times this (1) */
    double part_size;           /* for contact_time's auto: the part's
                                   pd_contact_time_auto_size */
    int material_ranged;        /* mu, restitution or contact_time is a range:
                                   each drop sets its own (pd_drop_material) */
    int compliant_any;          /* some drop may be compliant: work areas need it */
    pd_compliant_table table;   /* the impulse engine's laws across the
                                   restitution's range, when it has one */
    double patch_omega;         /* m rad/s: the contact patch's radius under
                                   the part's weight times the law's omega */
} pd_sim_model;

typedef struct pd_drop_work {
    pd_impact_work *impact;
    pd_ode *phase;              /* the sliding phases' integrator */
    pd_ode *phase_spin;         /* and theirs when spinning fast
                                   (pd_contact_phase_spins_fast) */
    pd_ode *pivot;              /* and the pivots' (contact_pivot.h) */
    pd_engine_world *world;     /* the stepping engine's, or NULL */
    pd_compliant_work *compliant_work; /* with model->compliant_any, else NULL */
    const pd_engine *engine;
    int contacts[PD_MAX_CONTACTS];
    double rest_depth;          /* m: the last drop's deepest lasting contact:
                                   a resting contact found below the floor, or
                                   a compliant contact older than its duration */
    double contact_time;        /* this drop's: s, resolved (the model's unless ranged) */
    int compliant_on;           /* this drop's impacts of several contacts are compliant */
    pd_compliant compliant;     /* and their law */
    pd_settle settle;           /* the model's, but for this drop's contact
                                   patch, which its law's stiffness sets */
    double top_time;            /* this drop's pd_sim_model.top_time */
    double energy_rise;         /* the last drop's largest rise of its energy
                                   (kinetic per weight plus the centre's
                                   height) above its lowest so far, per L:
                                   about a rest fall at most, what a
                                   microcollision may turn into motion */
} pd_drop_work;

/* A drop's record stays marked so while it has not run to its end: never
 * started, or stopped part way by the cancel flag. Such a drop and every
 * drop after it are left out of a partial result (montecarlo.c). */
#define PD_END_NOT_RUN ((pd_drop_end)-1)

/* 1 if the run's cancel flag is set. Relaxed: the flag only asks the drops
 * to stop; no data is published through it (the records are joined with the
 * threads). Cheap enough to read at every step of a drop. */
static inline int pd_drop_cancelled(const pd_sim_options *o)
{
    return o->cancel && atomic_load_explicit(o->cancel, memory_order_relaxed) != 0;
}

pd_status pd_sim_model_build(const pd_part *part, const pd_static_result *poses,
                             const pd_scene *scene, const pd_sim_options *options,
                             pd_sim_model **model, pd_diag *diag);
void pd_sim_model_free(pd_sim_model *model);

/* pd_sim_model_build with every integration tolerance of the impulse
 * engine's impacts and contacts times tol_scale in (0, 1]: for tests that
 * the model converges as they tighten. */
pd_status pd_sim_model_build_tol(const pd_part *part, const pd_static_result *poses,
                                 const pd_scene *scene, const pd_sim_options *options,
                                 double tol_scale, pd_sim_model **model, pd_diag *diag);

pd_drop_work *pd_drop_work_alloc(const pd_sim_model *model, const pd_scene *scene);

/* Sets work's contact law (and a stepping engine's world) for a drop of
 * scene `drawn` (pd_scene_draw's: no ranges): the model's own when its
 * material is not ranged. */
pd_status pd_drop_material(const pd_sim_model *model, pd_drop_work *work, const pd_scene *drawn);
void pd_drop_work_free(pd_drop_work *work);

/* The release of drop `index`: its state (uniform or resting pose,
 * vibration, belt velocity, lowest point at the drop height) drawn from the
 * drop's own stream (options->seed, index), and its record reset (out->q0 the
 * part frame's orientation, no pose yet). init_cdf (nposes cumulative
 * probabilities) makes it start resting on a pose drawn from it, turned at
 * random about the vertical (the paper's bootstrap); NULL starts from a
 * uniform orientation. */
void pd_drop_release(const pd_sim_model *model, const pd_scene *scene,
                     const pd_sim_options *options, long index, const double *init_cdf,
                     pd_state *s, pd_trial *out);

/* Hands drop `index`'s state s at time t, after `event`, to options->trace
 * if that drop is traced (pd_trace_row, its energy under gravity);
 * nothing otherwise. */
void pd_drop_trace_state(const pd_sim_model *model, const pd_sim_options *options, double gravity,
                         long index, double t, const pd_state *s, const char *event);

/* Marks the drop's record failed at that stage with that status. */
static inline void pd_drop_failed(pd_trial *out, pd_drop_stage stage, pd_status status)
{
    out->end = PD_END_FAILED;
    out->stage = stage;
    out->status = status;
}

#endif
