/* drop_step.c: a drop on a stepping engine (ODE, Bullet), for the
 * cross-check. Same release as the impulse simulator's drop of the same index
 * (pd_drop_release), fixed steps of the engine, and the same decision of
 * where it ends, with one guard and one addition for soft contacts.
 *
 * The guard: a stepping engine's contacts are soft and can feed energy back,
 * so the energy test alone is not trusted: the part must also lie on the
 * facet of its basin, tilted less than PD_TOL_REST_TILT.
 *
 * The addition: a resting part's energy reads up to the contact's sink below
 * or above lying still on its facet, so a barrier lower than that above the
 * facet (two stable facets meeting at a shallow ridge: 3e-5 of the size for
 * 0.9 degrees) is never passed by the energy test, and such a part rocked
 * until the time limit. The energy resolution of a soft contact is what
 * rest_fall allows for; with the energy within 2 rest_fall of lying still on
 * the facet of the basin the part is in (and the tilt guard passed), it lies
 * on that facet as still as the engine can tell, and the drop ends there.
 * This adds decisions only where the basin's barrier is below the facet's
 * height plus 3 rest_fall: a higher barrier has the energy test pass first
 * (energy + rest_fall < barrier), so the addition never overrides a basin
 * the engine can resolve.
 *
 * And one hold: the energy test reads the part's motion and height, not
 * what its contacts' springs hold, so at the bottom of a bounce (the part
 * still, its contacts compressed) a part landing on a facet passes it with
 * the energy of the fall stored in the floor, to be given back (a cube
 * dropped resting on a face ended there in about half its drops, before a
 * rebound with several times the energy it needs to tip: measured in
 * docs/engines-crosscheck.md, "The resting cube: which engine is right").
 * A decision stands only when it has held on every step for one contact
 * time of the drop, longer than a bounce's turning point lasts; at rest it
 * holds throughout. Only where the step resolves the contact
 * (PD_ENGINE_CONTACT_STEPS): at a coarser step the engine keeps its own
 * rigid contact, which stores nothing, and its resting state may flicker
 * from step to step, never holding a contact time (a tiny cube on ODE at
 * 1 ms, test_hard_parts.c). */
#include <math.h>
#include "base/fail.h"
#include "base/vec3.h"
#include "engines/engine_contact.h"
#include "settle/settle.h"
#include "sim/drop_step.h"
#include "sim/sim_tol.h"

/* Energy per unit weight, m: the height the centre of mass could reach. */
static double energy_height(const pd_body *b, const pd_state *s, double g)
{
    double rot = b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                 b->moment[2] * s->w.z * s->w.z;
    return s->x.z + (v3_dot(s->v, s->v) + rot / b->mass) / (2.0 * g);
}

/* 1 and the pose if the drop in state s ends: decided by energy against the
 * basin's barrier, or lying still on the facet of its basin (see the top);
 * in both cases tilted less than PD_TOL_REST_TILT from the pose's facet. 0
 * if not yet, -1 on failure. */
static int at_rest(const pd_sim_model *m, const pd_state *s, double g, int *hint, int *pose)
{
    const pd_settle *st = &m->settle;
    int f, d = pd_settle_decided_at(st, s, g, hint, pose, &f);
    if (d < 0)
        return -1;
    if (d == 0) {
        if (f < 0)
            return 0;
        *pose = st->pose_of[st->descent->facets[f].rest];
        if (*pose < 0 ||
            !(energy_height(m->body, s, g) < st->poses->poses[*pose].height + 2.0 * st->rest_fall))
            return 0;
    }
    return pd_settle_tilt(st, s, *pose) < PD_TOL_REST_TILT;
}

void pd_drop_run_stepping(const pd_sim_model *m, pd_drop_work *w, const pd_scene *sc,
                          const pd_sim_options *o, long index, const double *init_cdf,
                          pd_trial *out)
{
    pd_state s;
    pd_drop_release(m, sc, o, index, init_cdf, &s, out);
    pd_status st = m->engine->reset(w->world, &s);
    pd_drop_trace_state(m, o, sc->gravity, index, 0.0, &s, "release");
    if (st != PD_OK) {
        pd_drop_failed(out, PD_STAGE_ENGINE_RESET, st);
        return;
    }
    /* At most PD_STEPS_MAX + 1 (sim_model.c refuses more), so a long holds it. */
    long steps = (long)fmin(o->time_limit / m->dt, PD_STEPS_MAX) + 1;
    int hint = 0;
    /* Steps a decision must hold (see the top), and those it has held on
     * the same pose. */
    double hold = w->contact_time >= PD_ENGINE_CONTACT_STEPS * m->dt
                      ? ceil(w->contact_time / m->dt) : 0.0;
    long held = 0;
    int held_pose = -1;
    for (long k = 0; k < steps; k++) {
        if (pd_drop_cancelled(o)) {
            out->end = PD_END_NOT_RUN;
            return;
        }
        int pose, d = at_rest(m, &s, sc->gravity, &hint, &pose);
        if (d < 0) {
            pd_drop_failed(out, PD_STAGE_SETTLE, PD_ERR_INTERNAL);
            return;
        }
        if (d == 0) {
            held = 0;
        } else {
            held = held > 0 && pose == held_pose ? held + 1 : 1;
            held_pose = pose;
        }
        if (d > 0 && (double)held > hold) {
            out->pose = pose;
            out->end = PD_END_SETTLED;
            pd_drop_trace_state(m, o, sc->gravity, index, out->time, &s, "end");
            return;
        }
        if ((st = m->engine->step(w->world, &s)) != PD_OK) {
            pd_drop_failed(out, PD_STAGE_ENGINE_STEP, st);
            return;
        }
        out->time = (double)(k + 1) * m->dt;
        pd_drop_trace_state(m, o, sc->gravity, index, out->time, &s, "step");
    }
    out->end = PD_END_TIME_LIMIT;
}
