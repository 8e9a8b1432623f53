/* sim_model.c: the model a run of drops is built on, a thread's work area,
 * and every engine's release of a drop (see sim_model.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/quat.h"
#include "base/rng.h"
#include "base/vec3.h"
#include "contact/contact_phase.h"
#include "engines/engine_contact.h"
#include "base/base_tol.h"
#include "posedrop/tolerances.h"
#include "sim/sim_tol.h"
#include "sim/scene.h"
#include "sim/sim_model.h"

void pd_sim_model_free(pd_sim_model *m)
{
    if (!m)
        return;
    pd_settle_free(&m->settle);
    pd_body_free(m->body);
    free(m);
}

/* The high end of scene parameter k, its field where fixed. */
static double param_hi(const pd_scene *sc, pd_scene_param k, double fixed)
{
    return sc->range[k].kind == PD_DIST_FIXED ? fixed : sc->range[k].hi;
}

/* The longest body b can spin as a top on one vertex before drilling
 * friction over a patch of radius `patch` stops it (docs/limits.md,
 * "Tops"), s; 0 where nothing drills. Only the drilling couple, (2/3) mu a
 * N, has a moment about the vertical through a sticking vertex (gravity's
 * is horizontal, the contact's forces act at it), and N is the weight on
 * average over a spin that lasts, so the vertical angular momentum about
 * the vertex, Lz, falls at (2/3) mu a m g. Lz is at most sqrt(2 E Imax),
 * Imax = I3 + m rmax^2 bounding the moment about any axis through a
 * vertex and E the most energy a drop can have: its fall from the highest
 * drop height with the centre of mass rmax above the lowest vertex, the
 * fastest belt and tumble; mu the lowest. */
static double top_spin_down(const pd_body *b, const pd_scene *sc, double patch)
{
    double g = sc->gravity, m = b->mass, mu = sc->range[PD_PARAM_MU].kind == PD_DIST_FIXED
                                                  ? sc->mu
                                                  : sc->range[PD_PARAM_MU].lo;
    if (!(mu > 0.0 && patch > 0.0))
        return 0.0;
    const pd_dist *belt = &sc->range[PD_PARAM_BELT_SPEED];
    double v = belt->kind == PD_DIST_FIXED ? fabs(sc->belt_speed)
                                           : fmax(fabs(belt->lo), fabs(belt->hi));
    double w = param_hi(sc, PD_PARAM_TUMBLE, sc->tumble);
    double E = m * g * (param_hi(sc, PD_PARAM_HEIGHT, sc->height) + b->rmax) + 0.5 * m * v * v +
               0.5 * b->moment[2] * w * w;
    double Lz = sqrt(2.0 * E * (b->moment[2] + m * b->rmax * b->rmax));
    return Lz / (2.0 / 3.0 * mu * patch * m * g);
}

/* A stepping engine's automatic step (dt 0): pd_engine_dt_auto for the
 * shortest contact the scene can draw and its fastest fall, but never so
 * short that a drop run to its time limit takes more than PD_STEPS_MAX
 * steps (a part of a fraction of a millimetre, whose contact is
 * microseconds); the engines then keep their own contact, the scene law's
 * rigid limit, as they do for any contact their step does not resolve. */
static double step_auto(const pd_sim_model *m, const pd_part *part, const pd_scene *scene,
                        const pd_dist *ct)
{
    double t_lo = ct->kind == PD_DIST_FIXED ? m->contact_time
                  : ct->auto_multiple       ? ct->lo * pd_contact_time_auto(m->part_size)
                                            : ct->lo;
    double dt = pd_engine_dt_auto(t_lo, pd_engine_fall_speed(scene, part->size),
                                  pd_engine_hull_width(part->hull), PD_SIM_DT_MAX);
    return fmax(dt, m->time_limit / PD_STEPS_MAX);
}

pd_status pd_sim_model_build(const pd_part *part, const pd_static_result *poses,
                             const pd_scene *scene, const pd_sim_options *options,
                             pd_sim_model **model, pd_diag *diag)
{
    return pd_sim_model_build_tol(part, poses, scene, options, 1.0, model, diag);
}

pd_status pd_sim_model_build_tol(const pd_part *part, const pd_static_result *poses,
                                 const pd_scene *scene, const pd_sim_options *options,
                                 double tol_scale, pd_sim_model **model, pd_diag *diag)
{
    if (!(tol_scale > 0.0 && tol_scale <= 1.0))
        return pd_fail(diag, PD_ERR_RANGE, "tolerance scale %g outside (0, 1]", tol_scale);
    pd_sim_model *m = calloc(1, sizeof *m);
    if (!m)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop model");
    m->tol_scale = tol_scale;
    m->engine = pd_engine_get(options->engine);
    if (options->engine != PD_ENGINE_IMPULSE && !m->engine) {
        free(m);
        return pd_fail(diag, PD_ERR_UNAVAILABLE, "the %s engine is not in this program",
                       options->engine == PD_ENGINE_BULLET ? "Bullet" : "requested");
    }
    m->time_limit = options->time_limit > 0 ? options->time_limit
                                            : pd_time_limit_auto(part->size, scene);
    /* Auto, fixed or as a range's multiple, from one length, so that a
     * zero-width range gives the fixed run's bytes. */
    m->part_size = pd_contact_time_auto_size(part);
    m->contact_time = scene->contact_time == PD_CONTACT_TIME_AUTO
                          ? pd_contact_time_auto(m->part_size)
                          : scene->contact_time;
    const pd_dist *ct = &scene->range[PD_PARAM_CONTACT_TIME], *e = &scene->range[PD_PARAM_RESTITUTION];
    if (m->engine)
        m->dt = options->dt > 0 ? options->dt : step_auto(m, part, scene, ct);
    if (m->engine && options->dt > 0 && m->time_limit / m->dt > PD_STEPS_MAX) {
        double dt = m->dt, limit = m->time_limit;
        free(m);
        return pd_fail(diag, PD_ERR_RANGE, "the %s engine would take %.3g steps of %g s per drop "
                       "to reach the time limit of %.6g s (for a part of size %g m), more than %g: "
                       "give a longer step (dt) or a shorter time limit",
                       options->engine == PD_ENGINE_BULLET ? "Bullet" : "ODE", limit / dt, dt,
                       limit, part->size, PD_STEPS_MAX);
    }
    const pd_dist *hr = &scene->range[PD_PARAM_HEIGHT];
    double h_hi = hr->kind == PD_DIST_FIXED ? scene->height : hr->hi;
    if (h_hi > PD_HEIGHT_SIZES_MAX * part->size) {
        free(m);
        return pd_fail(diag, PD_ERR_RANGE, "a drop height of %g m is %.3g times the part's size "
                       "(%.3g m), more than the %g at which a drop can be simulated (it would "
                       "bounce for hours of CPU, or fail): a part or height in the wrong unit?",
                       h_hi, h_hi / part->size, part->size, PD_HEIGHT_SIZES_MAX);
    }
    m->hull = part->hull;
    m->com = part->com;
    m->poses = poses;
    pd_status st = pd_body_build(part, &m->body, diag);
    const char *why = st == PD_OK && m->engine && m->engine->refuses
                          ? m->engine->refuses(m->body, part->hull, scene)
                          : NULL;
    if (why)
        st = pd_fail(diag, PD_ERR_UNAVAILABLE, "the %s engine cannot run this part: %s",
                     m->engine->name, why);
    if (st == PD_OK)
        st = pd_settle_build(part, m->body, poses, scene->gravity, &m->settle, diag);
    if (st == PD_OK && !m->engine) {
        /* The impulse engine puts every resting contact back onto the floor
         * and pays for it (src/sim/drop.c), so its energy reads low by what
         * an unpaid return may add at most, not by a rest fall; it tells
         * heights apart to its contact tolerance. */
        m->settle.margin = PD_REST_TURN_REL * m->body->size;
        m->settle.still = PD_TOL_CONTACT_REL * m->body->size;
    }
    m->material_ranged = scene->range[PD_PARAM_MU].kind != PD_DIST_FIXED ||
                         e->kind != PD_DIST_FIXED || ct->kind != PD_DIST_FIXED;
    double ct_hi = ct->kind == PD_DIST_FIXED ? m->contact_time
                   : ct->auto_multiple       ? ct->hi * pd_contact_time_auto(m->part_size)
                                             : ct->hi;
    /* A drawn duration obeys the value's range; auto itself is the part's
     * and has none. */
    if (st == PD_OK && ct->kind != PD_DIST_FIXED && ct_hi > 1.0)
        st = pd_fail(diag, PD_ERR_RANGE, "scene contact_time: the range reaches %g s for this "
                     "part: expected at most 1 s", ct_hi);
    m->compliant_any = !m->engine && ct_hi > 0.0;
    /* A contact carrying the part's weight at the part's mass sinks
     * g / omega^2 by the compliant law; a corner of radius R pressed that
     * deep touches over a patch of radius sqrt(R g) / omega (Hertz's
     * geometry, a^2 = R d). */
    m->patch_omega = sqrt(PD_CORNER_RADIUS_REL * part->size * scene->gravity);
    if (st == PD_OK && m->compliant_any && m->material_ranged) {
        double e_lo = e->kind == PD_DIST_FIXED ? scene->restitution : e->lo;
        double e_hi = e->kind == PD_DIST_FIXED ? scene->restitution : e->hi;
        st = pd_compliant_table_init(e_lo, e_hi, &m->table);
        if (st != PD_OK)
            st = pd_fail(diag, st, "the compliant contact law for restitution %g to %g could not "
                         "be set up", e_lo, e_hi);
    }
    if (st == PD_OK && !m->engine && m->contact_time > 0.0) {
        m->compliant_on = 1;
        st = pd_compliant_init(scene->restitution, m->contact_time, m->body, tol_scale,
                               &m->compliant);
        if (st != PD_OK)
            st = pd_fail(diag, st, "the compliant contact law for restitution %g and contact "
                         "time %g s could not be set up", scene->restitution, m->contact_time);
        else
            m->settle.patch = m->patch_omega / m->compliant.law.omega;
    }
    if (st == PD_OK)
        m->top_time = top_spin_down(m->body, scene, m->settle.patch);
    if (st != PD_OK) {
        pd_sim_model_free(m);
        return st;
    }
    /* A speed scale of the part: sqrt(g L), the speed of falling its own
     * size. Approaches slower by PD_TOL_APPROACH_REL are round-off of a
     * resolved contact, not a new impact. */
    m->v_eps = PD_TOL_APPROACH_REL * sqrt(scene->gravity * m->body->size);
    *model = m;
    return PD_OK;
}

pd_drop_work *pd_drop_work_alloc(const pd_sim_model *model, const pd_scene *scene)
{
    pd_drop_work *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    if (model->engine) {
        /* The engines see the contact time the run resolved, never the
         * "auto" marker. */
        pd_scene resolved = *scene;
        resolved.contact_time = model->contact_time;
        w->world = model->engine->world_alloc(model->body, model->hull, &resolved, model->dt);
    } else {
        w->impact = pd_impact_work_alloc_tol(model->tol_scale);
        w->phase = pd_contact_phase_ode_alloc_tol(model->tol_scale);
        w->phase_spin = pd_contact_phase_spin_ode_alloc_tol(model->tol_scale);
        w->pivot = pd_contact_pivot_ode_alloc_tol(model->tol_scale);
        if (model->compliant_any)
            w->compliant_work = pd_compliant_work_alloc(model->body);
    }
    if ((!w->impact || !w->phase || !w->phase_spin || !w->pivot ||
         (model->compliant_any && !w->compliant_work)) &&
        !w->world) {
        pd_impact_work_free(w->impact);
        pd_ode_free(w->phase);
        pd_ode_free(w->phase_spin);
        pd_ode_free(w->pivot);
        pd_compliant_work_free(w->compliant_work);
        free(w);
        return NULL;
    }
    w->engine = model->engine;
    w->contact_time = model->contact_time;
    w->compliant_on = model->compliant_on;
    w->compliant = model->compliant;
    w->settle = model->settle;
    w->top_time = model->top_time;
    return w;
}

pd_status pd_drop_material(const pd_sim_model *m, pd_drop_work *w, const pd_scene *drawn)
{
    if (!m->material_ranged)
        return PD_OK;
    w->contact_time = drawn->contact_time == PD_CONTACT_TIME_AUTO
                          ? pd_contact_time_auto(m->part_size)
                          : drawn->contact_time;
    if (m->engine) {
        pd_scene resolved = *drawn;
        resolved.contact_time = w->contact_time;
        return m->engine->material(w->world, &resolved);
    }
    /* The patch and the top's spin-down follow the drop's own law and
     * values, as a fixed run's follow its scene's: a zero-width range then
     * gives the fixed run's bytes. */
    w->compliant_on = w->contact_time > 0.0;
    w->settle.patch = 0.0;
    if (w->compliant_on) {
        pd_compliant_law law;
        pd_compliant_table_law(&m->table, drawn->restitution, w->contact_time, &law);
        pd_compliant_from_law(&law, m->body, m->tol_scale, &w->compliant);
        w->settle.patch = m->patch_omega / w->compliant.law.omega;
    }
    w->top_time = top_spin_down(m->body, drawn, w->settle.patch);
    return PD_OK;
}

void pd_drop_work_free(pd_drop_work *w)
{
    if (!w)
        return;
    pd_impact_work_free(w->impact);
    pd_ode_free(w->phase);
    pd_ode_free(w->phase_spin);
    pd_ode_free(w->pivot);
    pd_compliant_work_free(w->compliant_work);
    if (w->world)
        w->engine->world_free(w->world);
    free(w);
}

/* --- initial state ----------------------------------------------------------- */

/* The rotation turning unit vector a onto unit vector b by the shortest arc. */
static pd_quat quat_between(pd_vec3 a, pd_vec3 b)
{
    pd_vec3 axis = v3_cross(a, b);
    double s = v3_norm(axis), c = v3_dot(a, b);
    if (s < PD_TOL_ANGLE) { /* parallel or opposite within round-off */
        if (c > 0.0)
            return quat_identity();
        pd_vec3 any = fabs(a.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
        return quat_axis_angle(v3_unit(v3_cross(a, any)), M_PI);
    }
    return quat_axis_angle(v3_scale(axis, 1.0 / s), atan2(s, c));
}

static void initial_state(const pd_sim_model *m, const pd_scene *sc, pd_rng *rng,
                          uint64_t seed, long index, const double *init_cdf, pd_state *s,
                          double q0[4])
{
    const pd_body *b = m->body;
    pd_quat q;
    if (init_cdf) {
        /* The paper's belt: resting on a pose drawn from the estimate, turned
         * at random about the vertical. */
        double u = pd_rng_uniform(rng);
        int k = 0;
        while (k + 1 < m->poses->nposes && u >= init_cdf[k])
            k++;
        pd_vec3 n = quat_rotate_inv(b->frame, m->poses->poses[k].normal);
        pd_quat down = quat_between(n, v3(0, 0, -1));
        q = quat_mul(quat_axis_angle(v3(0, 0, 1), 2.0 * M_PI * pd_rng_uniform(rng)), down);
    } else {
        double r[4];
        pd_rng_quaternion(rng, r);
        q = quat(r[0], r[1], r[2], r[3]);
    }
    if (sc->vibration > 0.0) {
        pd_vec3 axis = pd_rng_unit_vector(rng);
        q = quat_mul(quat_axis_angle(axis, sc->vibration * pd_rng_uniform(rng)), q);
    }
    q = quat_normalize(q);
    s->q = q;
    s->x = v3(0, 0, 0);
    s->v = v3(sc->belt_speed, 0, 0);
    s->w = v3(0, 0, 0);
    if (sc->tumble > 0.0) {
        /* From the parameters' stream: a run without tumble draws nothing
         * more from the drop's own. */
        double a[3];
        pd_scene_tumble_axis(seed, index, a);
        s->w = quat_rotate_inv(q, v3_scale(v3(a[0], a[1], a[2]), sc->tumble));
    }
    /* Lowest point at the drop height. */
    int low = pd_body_support(b, quat_rotate_inv(q, v3(0, 0, 1)), 0);
    s->x.z = sc->height - pd_body_vertex_world(b, s, low).z;
    /* The orientation of the part's own (file) frame, for --trials. */
    pd_quat qp = quat_mul(q, quat_conj(b->frame));
    q0[0] = qp.w;
    q0[1] = qp.x;
    q0[2] = qp.y;
    q0[3] = qp.z;
}

void pd_drop_release(const pd_sim_model *m, const pd_scene *sc, const pd_sim_options *o,
                     long index, const double *init_cdf, pd_state *s, pd_trial *out)
{
    pd_rng rng;
    pd_rng_init(&rng, o->seed, (uint64_t)index);
    initial_state(m, sc, &rng, o->seed, index, init_cdf, s, out->q0);
    out->pose = -1;
    out->collisions = 0;
    out->end = PD_END_FAILED;
    out->stage = PD_STAGE_NONE;
    out->status = PD_OK;
    out->time = 0.0;
}

void pd_drop_trace_state(const pd_sim_model *m, const pd_sim_options *o, double gravity, long index,
                         double t, const pd_state *s, const char *event)
{
    if (!o->trace || index != o->trace_drop)
        return;
    const pd_body *b = m->body;
    double g = fabs(gravity);
    pd_trace_row r;
    r.t = t;
    r.x[0] = s->x.x, r.x[1] = s->x.y, r.x[2] = s->x.z;
    pd_quat q = quat_normalize(s->q);
    r.q[0] = q.w, r.q[1] = q.x, r.q[2] = q.y, r.q[3] = q.z;
    r.v[0] = s->v.x, r.v[1] = s->v.y, r.v[2] = s->v.z;
    pd_vec3 w = quat_rotate(q, s->w);
    r.w[0] = w.x, r.w[1] = w.y, r.w[2] = w.z;
    double rot = b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                 b->moment[2] * s->w.z * s->w.z;
    r.energy = s->x.z + (v3_dot(s->v, s->v) + rot / b->mass) / (2.0 * g);
    double low = HUGE_VAL, near = PD_TOL_REST_FALL_REL * b->size;
    r.contacts = 0;
    for (int i = 0; i < b->nverts; i++) {
        double z = s->x.z + quat_rotate(q, b->verts[i]).z;
        low = fmin(low, z);
        r.contacts += z <= near;
    }
    r.depth = -low;
    r.event = event;
    o->trace(o->trace_user, &r);
}
