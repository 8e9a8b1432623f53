/* drop.h (private): one simulated drop, and what it needs.
 *
 * The model is built once per run from the part (rigid body in principal
 * axes, the pose table, the basins' energy barriers) and shared read-only by
 * all threads; each thread owns a work area (ODE stepper, scratch), so the
 * drop loop never allocates. */
#ifndef PD_DROP_H
#define PD_DROP_H

#include <stdint.h>
#include "dynamics/body.h"
#include "base/rng.h"
#include "posedrop/sim.h"

typedef struct pd_sim_model pd_sim_model;
typedef struct pd_drop_work pd_drop_work;

pd_status pd_sim_model_build(const pd_part *part, const pd_static_result *poses,
                             const pd_scene *scene, const pd_sim_options *options,
                             pd_sim_model **model, pd_diag *diag);
void pd_sim_model_free(pd_sim_model *model);

pd_drop_work *pd_drop_work_alloc(const pd_sim_model *model, const pd_scene *scene);
void pd_drop_work_free(pd_drop_work *work);

/* Drop number `index` of a run seeded `seed`: everything random about it
 * comes from that stream. init_cdf (nposes cumulative probabilities) makes it
 * start resting on a pose drawn from it, turned at random about the vertical
 * (the paper's bootstrap); NULL starts from a uniform orientation. *energy_gain
 * counts collisions that would have added energy, *fallbacks those the sliding
 * integrator could not finish (both resolved otherwise, see drop.c). */
void pd_drop_run(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                 const pd_sim_options *options, long index, const double *init_cdf,
                 pd_trial *out, long *energy_gain, long *fallbacks);

/* Resolves a collision of the part in state s with the floor at the body
 * vertices contacts[0..nc): approaching contacts are resolved as one impact at
 * their centroid weighted by approach speed, repeatedly until none approaches
 * (see drop.c). Updates s's velocities; *impacts counts impulses applied,
 * *gain and *fallbacks as for pd_drop_run. The model's body gives the vertex
 * numbering (pd_sim_model_body). */
pd_status pd_drop_collide(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                          pd_state *s, const int *contacts, int nc, int *impacts, long *gain,
                          long *fallbacks);

/* The release of drop `index`: its state (uniform or bootstrap pose,
 * vibration, belt velocity, lowest point at the drop height) drawn from the
 * drop's own stream (options->seed, index), and its record reset (out->q0 the
 * part frame's orientation, no pose yet). Shared by every engine, so engines
 * can be compared drop by drop. */
void pd_drop_release(const pd_sim_model *model, const pd_scene *scene,
                     const pd_sim_options *options, long index, const double *init_cdf,
                     pd_state *s, pd_trial *out);

/* 1 and the pose index if the outcome of state s is decided (energy below its
 * basin's barrier, see drop.c), 0 if not yet, -1 on failure (of the descent,
 * which is not taken when the energy is above every barrier). hint speeds up
 * successive calls. */
int pd_drop_decided(const pd_sim_model *model, const pd_state *s, double gravity, int *hint,
                    int *pose);

/* The part's tilt in state s from the facet of the basin it would rest in:
 * the angle between gravity and that facet's normal, rad. */
double pd_drop_tilt(const pd_sim_model *model, const pd_state *s, int pose);

/* The stepping engines' drop (drop_step.c): the same release, then fixed
 * steps of the engine in work until it lies on a facet (tilt below
 * PD_TOL_REST_TILT) with its energy below its basin's barrier, or the time
 * limit. */
void pd_drop_run_stepping(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                          const pd_sim_options *options, long index, const double *init_cdf,
                          pd_trial *out);

/* The model's rigid body (principal frame, hull vertices). */
const pd_body *pd_sim_model_body(const pd_sim_model *model);

#endif
