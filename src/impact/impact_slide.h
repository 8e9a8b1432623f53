/* impact_slide.h: a collision's sliding phase (impact_slide.c), on the
 * collision's state (impact_collision.h). */
#ifndef PD_IMPACT_SLIDE_H
#define PD_IMPACT_SLIDE_H

#include "base/gsl_adapter.h"
#include "impact/impact_collision.h"

/* Sliding (eq. 14) from the current state until the collision ends (done
 * set) or the slip vanishes or joins the diverging ray (the state there,
 * done clear); *nsteps counts integrator steps. PD_OK or a failure status:
 * PD_ERR_NO_CONVERGENCE beyond PD_IMPACT_MAX_STEPS, or the integrator's. */
pd_status pd_impact_slide(collision *c, pd_ode *ode, int *nsteps);

#endif
