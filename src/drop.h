/* drop.h (private): one simulated drop, and what it needs.
 *
 * The model is built once per run from the part (rigid body in principal
 * axes, the pose table, the basins' energy barriers) and shared read-only by
 * all threads; each thread owns a work area (ODE stepper, scratch), so the
 * drop loop never allocates. */
#ifndef PD_DROP_H
#define PD_DROP_H

#include <stdint.h>
#include "body.h"
#include "posedrop/sim.h"

typedef struct pd_sim_model pd_sim_model;
typedef struct pd_drop_work pd_drop_work;

pd_status pd_sim_model_build(const pd_part *part, const pd_static_result *poses,
                             const pd_scene *scene, pd_sim_model **model, pd_diag *diag);
void pd_sim_model_free(pd_sim_model *model);

pd_drop_work *pd_drop_work_alloc(const pd_sim_model *model);
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

/* The model's rigid body (principal frame, hull vertices). */
const pd_body *pd_sim_model_body(const pd_sim_model *model);

#endif
