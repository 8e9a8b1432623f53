/* drop_step.c: a drop on a stepping engine (ODE, Bullet), for the
 * cross-check. Same release as the impulse simulator's drop of the same index
 * (pd_drop_release), fixed steps of the engine, and the same decision of
 * where it ends. A stepping engine's contacts are soft and can feed energy
 * back, so the energy test alone is not trusted: the part must also lie on
 * the facet of its basin, tilted less than PD_TOL_REST_TILT. */
#include "base/fail.h"
#include "settle/settle.h"
#include "sim/drop_step.h"
#include "posedrop/tolerances.h"

void pd_drop_run_stepping(const pd_sim_model *m, pd_drop_work *w, const pd_scene *sc,
                          const pd_sim_options *o, long index, const double *init_cdf,
                          pd_trial *out)
{
    pd_state s;
    pd_drop_release(m, sc, o, index, init_cdf, &s, out);
    if (m->engine->reset(w->world, &s) != PD_OK)
        return;
    long steps = (long)(o->time_limit / m->dt) + 1;
    int hint = 0;
    for (long k = 0; k < steps; k++) {
        int pose, d = pd_settle_decided(&m->settle, &s, sc->gravity, &hint, &pose);
        if (d < 0)
            return;
        if (d > 0 && pd_settle_tilt(&m->settle, &s, pose) < PD_TOL_REST_TILT) {
            out->pose = pose;
            out->end = PD_END_SETTLED;
            return;
        }
        if (m->engine->step(w->world, &s) != PD_OK)
            return;
        out->time = (double)(k + 1) * m->dt;
    }
    out->end = PD_END_TIME_LIMIT;
}
