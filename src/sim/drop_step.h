/* drop_step.h (private): a drop on a stepping engine (ODE, Bullet). */
#ifndef PD_DROP_STEP_H
#define PD_DROP_STEP_H

#include "sim/sim_model.h"

/* The same release as the impulse simulator's drop of the same index, then
 * fixed steps of the engine in work until it lies on the facet of its basin
 * (tilt below PD_TOL_REST_TILT) with its energy below the basin's barrier or
 * within the contact's resolution of lying still there (drop_step.c), or
 * the time limit. */
void pd_drop_run_stepping(const pd_sim_model *model, pd_drop_work *work, const pd_scene *scene,
                          const pd_sim_options *options, long index, const double *init_cdf,
                          pd_trial *out);

#endif
