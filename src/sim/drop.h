/* drop.h (private): one simulated drop on whichever engine the model names:
 * the impulse simulator's drop loop (drop.c) or a stepping engine's
 * (drop_step.c). */
#ifndef PD_DROP_H
#define PD_DROP_H

#include "sim/sim_model.h"

/* Drop number `index` of a run seeded options->seed: everything random
 * about it comes from that stream (pd_drop_release). *energy_gain counts
 * collisions that would have added energy, *fallbacks those the sliding
 * integrator could not finish (both resolved otherwise, see drop.c). */
void pd_drop_run(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                 const pd_sim_options *options, long index, const double *init_cdf,
                 pd_trial *out, long *energy_gain, long *fallbacks);

/* Resolves a collision of the part in state s with the floor at the body
 * vertices contacts[0..nc): approaching contacts are resolved as one impact at
 * their centroid weighted by approach speed, repeatedly until none approaches
 * (see drop.c). Updates s's velocities; *impacts counts impulses applied,
 * *gain and *fallbacks as for pd_drop_run. model->body gives the vertex
 * numbering. */
pd_status pd_drop_collide(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                          pd_state *s, const int *contacts, int nc, int *impacts, long *gain,
                          long *fallbacks);

#endif
