/* drop.c: one simulated drop (paper, section 5), from release to the moment
 * its outcome can no longer change.
 *
 * Flight is closed form (flight.c) and the next impact is found by
 * conservative advancement (flight_impact.c), so there is no time step
 * between contacts. What happens at a contact depends on how many vertices
 * share it. A lone vertex striking the floor is resolved by the frictional
 * impulse law (impact.c), exact. When more than one vertex touches, or
 * reaches the floor within the scene's contact_time of the first, the
 * impact is compliant (contact/compliant.c): each vertex below the floor
 * pushes by a Hunt-Crossley law fixed by the restitution and the contact
 * duration, with Coulomb friction, and vertices that arrive meanwhile join;
 * a face landing nearly flat lands as a whole, as a real part's does
 * (docs/contact.md). The compliant run goes on through lasting face contact
 * until the part separates, rests on a vertex or an edge, or is decided.
 * With contact_time 0 (the paper's rigid model) touching vertices are
 * resolved as one collision at their centroid weighted by approach speed,
 * the set checked again until none approaches: a face landing flat without
 * spin then gets the single impulse through its centre that Poisson's law
 * gives a flat landing.
 *
 * Contact that lasts on one vertex or one edge, sliding or sticking, is a
 * contact phase (contact_phase.c): the exact continuous motion under its
 * contact forces, until a contact lifts, slips, sticks or another vertex
 * lands. What is left (contacts that chatter too much to enter a phase
 * losslessly, hand-overs; faces without compliance) is microcollisions: the
 * contact falls a rest fall, is stopped and put back onto the floor.
 *
 * A drop ends when its energy per unit weight (a height) falls below the
 * barrier of the basin it is in (basin.c): then no future can leave the
 * basin, so its stable pose is the outcome. That needs collisions that never
 * add energy: a Poisson collision that would (possible with friction in 3-D)
 * is redone by the energetic law, which cannot, and counted; a compliant
 * impact whose step would is scaled back, and counted. It also ends
 * when the part lies on a stable facet that sliding and spinning cannot tip
 * it from (flat_rest.c): then only the rocking energy must be below a
 * barrier, not the energy of the slide. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "dynamics/body.h"
#include "contact/contact_phase.h"
#include "base/fail.h"
#include "settle/settle.h"
#include "sim/drop.h"
#include "sim/drop_step.h"
#include "sim/sim_tol.h"
#include "dynamics/flight.h"
#include "impact/impact.h"
#include "posedrop/tolerances.h"
#include "base/vec3.h"

/* --- collisions ------------------------------------------------------------- */

/* World inverse inertia R diag(1/I) R^T. */
static void inv_inertia_world(const pd_body *b, pd_quat q, double J[3][3])
{
    double R[3][3];
    quat_to_matrix(q, R);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double s = 0.0;
            for (int k = 0; k < 3; k++)
                s += R[i][k] * b->inv_moment[k] * R[j][k];
            J[i][j] = s;
        }
}

/* Solves K p = b for symmetric positive definite K (Cramer's rule: K is
 * 3 x 3 and well conditioned, its eigenvalues within a few units of 1/m). */
static pd_vec3 solve3(const double K[3][3], pd_vec3 b)
{
    pd_vec3 c0 = v3(K[0][0], K[1][0], K[2][0]), c1 = v3(K[0][1], K[1][1], K[2][1]),
            c2 = v3(K[0][2], K[1][2], K[2][2]);
    double det = v3_dot(c0, v3_cross(c1, c2));
    return v3(v3_dot(b, v3_cross(c1, c2)) / det, v3_dot(c0, v3_cross(b, c2)) / det,
              v3_dot(c0, v3_cross(c1, b)) / det);
}

/* The impulse when the sliding integrator cannot finish (a slow approach to
 * sticking makes eq. 14 stiff; impact.h): stop the contact dead (K p = -u0),
 * which is inside the friction cone or is projected onto it along its own
 * tangential direction, then apply restitution to the normal part only.
 * Kinetic energy cannot rise: if the projection would make it, the normal
 * inelastic impulse alone is used. Counted, never silent. */
static pd_vec3 fallback_impulse(const double K[3][3], pd_vec3 u0, double mu, double e)
{
    pd_vec3 p = solve3(K, v3_neg(u0));
    double pt = hypot(p.x, p.y);
    if (pt > mu * p.z) {
        double dx = pt > 0 ? p.x / pt : 0, dy = pt > 0 ? p.y / pt : 0;
        pd_vec3 dir = v3(mu * dx, mu * dy, 1.0); /* on the cone, towards the stick impulse */
        double kz = K[2][0] * dir.x + K[2][1] * dir.y + K[2][2];
        p = v3_scale(dir, -u0.z / kz);
    }
    p.z *= 1.0 + e;
    pd_vec3 u1 = v3_add(u0, v3(K[0][0] * p.x + K[0][1] * p.y + K[0][2] * p.z,
                               K[1][0] * p.x + K[1][1] * p.y + K[1][2] * p.z,
                               K[2][0] * p.x + K[2][1] * p.y + K[2][2] * p.z));
    if (v3_dot(p, v3_add(u0, u1)) > 0.0)
        p = v3(0, 0, -(1.0 + e) * u0.z / K[2][2]);
    return p;
}

pd_status pd_drop_collide(const pd_sim_model *m, pd_drop_work *w, const pd_scene *sc,
                          pd_state *s, const int *contacts, int nc, int *impacts, long *gain,
                          long *fallbacks)
{
    const pd_body *b = m->body;
    double J[3][3];
    inv_inertia_world(b, s->q, J);
    pd_impact_law law = sc->law == PD_RESTITUTION_ENERGETIC ? PD_IMPACT_ENERGETIC : PD_IMPACT_POISSON;
    for (int round = 0; round < PD_MAX_ROUNDS; round++) {
        pd_vec3 ww = quat_rotate(s->q, s->w), c = v3(0, 0, 0);
        double wsum = 0.0;
        for (int i = 0; i < nc; i++) {
            pd_vec3 r = quat_rotate(s->q, b->verts[contacts[i]]);
            double uz = s->v.z + v3_cross(ww, r).z;
            if (uz < -m->v_eps) {
                c = v3_add(c, v3_scale(r, -uz));
                wsum -= uz;
            }
        }
        if (wsum == 0.0)
            return PD_OK;
        c = v3_scale(c, 1.0 / wsum);
        pd_vec3 u0 = v3_add(s->v, v3_cross(ww, c));
        double e = -u0.z <= w->settle.v_rest ? 0.0 : sc->restitution;
        double K[3][3];
        pd_impact_K(1.0 / b->mass, CONST_M3(J), c, K);
        pd_impact_result res;
        pd_status st = pd_impact_solve(w->impact, CONST_M3(K), u0, sc->mu, e, law, &res);
        if (st == PD_OK && res.energy_gain && law == PD_IMPACT_POISSON) {
            (*gain)++;
            st = pd_impact_solve(w->impact, CONST_M3(K), u0, sc->mu, e, PD_IMPACT_ENERGETIC, &res);
        }
        if (st == PD_ERR_NO_CONVERGENCE) {
            (*fallbacks)++;
            res.p = fallback_impulse(CONST_M3(K), u0, sc->mu, e);
        } else if (st != PD_OK) {
            return st;
        }
        s->v = v3_add(s->v, v3_scale(res.p, 1.0 / b->mass));
        ww = v3_add(ww, m3_vec(CONST_M3(J), v3_cross(c, res.p)));
        if (e == 0.0 && w->settle.patch > 0.0 && J[2][2] > 0.0) {
            /* Resting contact: drilling friction over its patch
             * (docs/contact.md), an angular impulse about the normal of at
             * most (2/3) mu a times the normal impulse, against the spin
             * and never reversing it, so that it only takes energy. An
             * impact keeps the rigid law (Poisson's; the compliant law's
             * limit but where friction turns or stops the slip). */
            double cap = 2.0 / 3.0 * sc->mu * w->settle.patch * res.p.z;
            double dl = fmax(-cap, fmin(cap, -ww.z / J[2][2]));
            ww = v3_add(ww, v3_scale(v3(J[0][2], J[1][2], J[2][2]), dl));
        }
        s->w = quat_rotate_inv(s->q, ww);
        (*impacts)++;
    }
    return PD_OK;
}

/* --- the drop ----------------------------------------------------------------- */

/* Moves the contacts[0..nc) of s that touch the floor (within the impact
 * search's contact tolerance) to the front, keeping their order, and returns
 * how many; *approach is the fastest speed at which one of them approaches
 * (0 if none does). The rest would only arrive within the search's window. */
static int keep_touching(const pd_body *b, const pd_state *s, int *contacts, int nc,
                         double *approach)
{
    pd_vec3 ww = quat_rotate(s->q, s->w);
    double tol = PD_TOL_CONTACT_REL * b->size;
    int n = 0;
    *approach = 0.0;
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = quat_rotate(s->q, b->verts[contacts[i]]);
        if (s->x.z + r.z > tol)
            continue;
        *approach = fmax(*approach, -(s->v.z + v3_cross(ww, r).z));
        int c = contacts[i];
        memmove(contacts + n + 1, contacts + n, (size_t)(i - n) * sizeof *contacts);
        contacts[n++] = c;
    }
    return n;
}

/* The slowest rate at which the contacts[0..nc) of s rise from the floor,
 * m/s (negative when one approaches; HUGE_VAL for none). */
static double touching_rise(const pd_body *b, const pd_state *s, const int *contacts, int nc)
{
    pd_vec3 ww = quat_rotate(s->q, s->w);
    double rise = HUGE_VAL;
    for (int i = 0; i < nc; i++) {
        pd_vec3 r = quat_rotate(s->q, b->verts[contacts[i]]);
        rise = fmin(rise, s->v.z + v3_cross(ww, r).z);
    }
    return rise;
}

/* Kinetic plus potential energy per unit weight: a height, m. */
static double energy_height(const pd_body *b, const pd_state *s, double g)
{
    return pd_body_kinetic(b, s) / (b->mass * g) + s->x.z;
}

/* Lifts s by `lift` back onto the floor, paying out of its kinetic energy
 * for the part of the lift that the centre of mass did not fall (`fell`:
 * how far it fell in the rest step just taken; anything below 0 when no
 * rest step led here). The height the centre fell became speed that the
 * collision which follows then stops, as a sinking contact would have lost
 * it; but when the part turned
 * meanwhile the vertex went deeper than the centre fell, and lifting by the
 * difference for free, repeated, kept rocking parts going for ever (a coin
 * upright on its rim, twisting: the same energy after every 3 contacts
 * for 150 s). Slowing the whole motion by the factor that removes m g
 * (lift - fell) leaves the energy where the flight left it plus what the
 * collision will stop. */
static void lift_onto_floor(const pd_body *b, pd_state *s, double g, double lift, double fell)
{
    s->x.z += lift;
    double ke = pd_body_kinetic(b, s), pe = b->mass * g * fmax(lift - fmax(fell, 0.0), 0.0);
    double k = ke > pe ? sqrt(1.0 - pe / ke) : 0.0;
    s->v = v3_scale(s->v, k);
    s->w = v3_scale(s->w, k);
}

/* The longest step, at most dt, over which no vertex falls by more than
 * depth, where the centre falls at speed vz at most: a vertex at r moves
 * vertically at vz plus (w x r).z, and (w x r).z is at most |w_h| rmax with
 * w_h the horizontal part of the world angular velocity (spin about the
 * vertical moves no vertex up or down). Torque-free motion turns w by at most
 * spin_accel wmax^2 per unit time (body.h), so over a step t a vertex falls
 * by at most (vz + |w_h| rmax) t + spin_accel wmax^2 rmax t^2 / 2. */
static double turn_step(const pd_body *b, const pd_state *s, double wmax, double vz, double depth,
                        double dt)
{
    pd_vec3 ww = quat_rotate(s->q, s->w);
    double lin = vz + hypot(ww.x, ww.y) * b->rmax;
    double quad = 0.5 * b->spin_accel * wmax * wmax * b->rmax;
    if ((lin + quad * dt) * dt <= depth)
        return dt;
    return 2.0 * depth / (lin + sqrt(lin * lin + 4.0 * quad * depth));
}

/* Plans the flight from s when *f_at < 0 (nothing planned since the motion
 * last changed) and sets *f_at to 0; with complete 0, only its bounds
 * (pd_flight_plan_bounds): the impact search solves the rotation when it
 * first needs it, and a search that finds a contact touching at once, which
 * leads straight to the next collision, never does. 0 when the plan fails,
 * the drop then marked failed. */
static int plan_if_stale(const pd_body *b, const pd_state *s, double g, pd_flight *f, double *f_at,
                         int complete, pd_trial *out)
{
    pd_status st = PD_OK;
    if (*f_at < 0.0) {
        st = pd_flight_plan_bounds(b, s, g, f);
        *f_at = 0.0;
    }
    if (st == PD_OK && complete && f->kind == PD_FLIGHT_BOUNDS)
        st = pd_flight_complete(b, f);
    if (st != PD_OK) {
        pd_drop_failed(out, PD_STAGE_FLIGHT, st);
        return 0;
    }
    return 1;
}

void pd_drop_run(const pd_sim_model *m, pd_drop_work *w, const pd_scene *sc,
                 const pd_sim_options *o, long index, const double *init_cdf, pd_trial *out,
                 long *energy_gain, long *fallbacks)
{
    /* The options as the drop runs them: an automatic time limit resolved
     * (the model's, for its part and scene). */
    pd_sim_options run = *o;
    /* Under an automatic limit, the time a part spends spinning on one
     * vertex under drilling friction (a top) is left out of it, up to the
     * longest such spin its energy allows: that time is the drilling's,
     * not the part's natural time, which the limit is made of. */
    double top_left = run.time_limit > 0 ? 0.0 : w->top_time;
    if (!(run.time_limit > 0))
        run.time_limit = m->time_limit;
    o = &run;
    if (m->engine) {
        pd_drop_run_stepping(m, w, sc, o, index, init_cdf, out);
        return;
    }
    pd_state s;
    pd_drop_release(m, sc, o, index, init_cdf, &s, out);
    pd_drop_trace_state(m, o, sc->gravity, index, 0.0, &s, "release");
    if (w->compliant_work)
        pd_compliant_work_watch(w->compliant_work, o->cancel);
    w->rest_depth = 0.0;
    double t = 0.0, g = sc->gravity;
    /* Resting contact advances by the time to fall rest_fall, so that a
     * vertex pressed on the floor by gravity meets it again with the speed
     * that fall gives (a microcollision) rather than at speed 0. */
    double dt_rest = sqrt(2.0 * w->settle.rest_fall / g);
    int hint = 0, phase_ok = 1, nc = 0;
    pd_flight f;
    double f_at = -1.0; /* time on f at which s lies; < 0: plan from s */
    /* 1 right after pd_drop_collide stopped because no contact approached:
     * s then sits where the last search found it, touching at
     * w->contacts[0..nc), and a new search and a new pass of the collision
     * would find the same set (without an impact window it depends on
     * positions alone, which an impulse leaves as they were) and nothing to
     * resolve, so both are skipped. */
    int resolved = 0;
    double e_low = HUGE_VAL;
    double rest_from = -HUGE_VAL; /* the centre's height before the rest step just taken */
    w->energy_rise = 0.0;
    pd_status st;
    for (;;) {
        if (pd_drop_cancelled(o)) {
            out->end = PD_END_NOT_RUN;
            break;
        }
        double e_now = energy_height(m->body, &s, g);
        e_low = fmin(e_low, e_now);
        w->energy_rise = fmax(w->energy_rise, (e_now - e_low) / m->body->size);
        int pose, d = pd_settle_outcome(&w->settle, &s, g, sc->mu, &hint, &pose);
        if (d < 0) {
            pd_drop_failed(out, PD_STAGE_SETTLE, PD_ERR_INTERNAL);
            break;
        }
        if (d > 0) {
            out->pose = pose;
            out->end = PD_END_SETTLED;
            break;
        }
        if (out->collisions >= o->max_collisions) {
            out->end = PD_END_COLLISION_LIMIT;
            break;
        }
        /* The flight from s: planned afresh after anything that changed the
         * motion, else the one s already lies on, at its time f_at. */
        if (!plan_if_stale(m->body, &s, g, &f, &f_at, 0, out))
            break;
        if (!resolved) {
            pd_impact imp;
            /* hint: the lowest vertex of s where decided_at looked the
             * descent up, else of an earlier state; a start for the search's
             * hill-climb either way. */
            if ((st = pd_flight_impact_from(m->body, &f, f_at, &s, hint, f_at + (o->time_limit - t),
                                            w->contact_time, w->contacts, PD_MAX_CONTACTS,
                                            &imp)) != PD_OK) {
                pd_drop_failed(out, PD_STAGE_IMPACT_SEARCH, st);
                break;
            }
            if (imp.kind == PD_IMPACT_NONE) {
                t = o->time_limit;
                out->end = PD_END_TIME_LIMIT;
                break;
            }
            if (imp.kind == PD_IMPACT_NOW && imp.height < 0.0) {
                /* Resting contact found below the floor after a rest step:
                 * back onto it, so that microcollisions do not sink the
                 * part step by step, paid for out of the motion. */
                w->rest_depth = fmax(w->rest_depth, -imp.height);
                lift_onto_floor(m->body, &s, g, -imp.height, rest_from - s.x.z);
                f_at = -1.0; /* planned by the rest step, if no impulse comes first */
            }
            if (imp.kind == PD_IMPACT_AT) {
                if ((st = pd_flight_eval(&f, imp.t, &s)) != PD_OK) {
                    pd_drop_failed(out, PD_STAGE_FLIGHT, st);
                    break;
                }
                t += imp.t - f_at;
                f_at = imp.t;
                pd_drop_trace_state(m, o, g, index, t, &s, "flight");
            }
            rest_from = -HUGE_VAL;
            nc = imp.ncontacts < PD_MAX_CONTACTS ? imp.ncontacts : PD_MAX_CONTACTS;
            if (w->compliant_on) {
                /* More than one vertex touching or arriving within a contact
                 * duration, one of them striking: a compliant impact, which
                 * the arriving ones join. Else the exact rigid law at the
                 * touching vertices alone: a single vertex's compliant
                 * impact tends to it as the duration shrinks, exactly but
                 * where friction turns the sliding (docs/contact.md, the
                 * rigid limit). */
                double approach;
                int ntouch = keep_touching(m->body, &s, w->contacts, nc, &approach);
                if (nc >= 2 && approach > w->settle.v_rest) {
                    pd_compliant_result cr;
                    st = pd_compliant_run(&w->compliant, w->compliant_work, &w->settle, sc, &s,
                                          o->time_limit - t, &cr);
                    if (st != PD_OK) {
                        pd_drop_failed(out, PD_STAGE_COMPLIANT, st);
                        break;
                    }
                    out->collisions++;
                    *energy_gain += cr.energy_gain;
                    w->rest_depth = fmax(w->rest_depth, cr.rest_depth);
                    t += cr.time;
                    pd_drop_trace_state(m, o, g, index, t, &s, "compliant");
                    f_at = -1.0;
                    phase_ok = 1;
                    if (cr.end == PD_COMPLIANT_CANCELLED) {
                        out->end = PD_END_NOT_RUN;
                        break;
                    }
                    if (cr.end == PD_COMPLIANT_DECIDED) {
                        out->pose = cr.pose;
                        out->end = PD_END_SETTLED;
                        break;
                    }
                    /* The run's last step may pass the limit (by less than
                     * a step) whatever way it ended: the time is spent. */
                    if (cr.end == PD_COMPLIANT_TIME || t >= o->time_limit) {
                        out->end = PD_END_TIME_LIMIT;
                        break;
                    }
                    continue;
                }
                nc = ntouch;
            }
            int before = out->collisions;
            if ((st = pd_drop_collide(m, w, sc, &s, w->contacts, nc, &out->collisions, energy_gain,
                                      fallbacks)) != PD_OK) {
                pd_drop_failed(out, PD_STAGE_COLLISION, st);
                break;
            }
            if (out->collisions != before) {
                pd_drop_trace_state(m, o, g, index, t, &s, "impact");
                /* Each round applies one impulse, so fewer than
                 * PD_MAX_ROUNDS means a round found nothing approaching. */
                resolved = out->collisions - before < PD_MAX_ROUNDS && w->contact_time == 0.0;
                f_at = -1.0;
                continue;
            }
        }
        resolved = 0;
        pd_phase phase;
        if (phase_ok && pd_contact_phase_start(&w->settle, sc, &s, w->contacts, nc, &phase)) {
            /* One vertex or one edge in lasting contact, sliding or
             * sticking: the exact continuous motion. It ends at an event the
             * microcollisions must resolve, so the next rest step is theirs
             * (no phase can start and stop at once forever). */
            double dt;
            f_at = -1.0;
            int top = phase.nc == 1 && phase.drill[0] != 0.0;
            pd_ode *ode = pd_contact_phase_spins_fast(m->body, g, &s) ? w->phase_spin : w->phase;
            if ((st = pd_contact_phase(&w->settle, ode, w->pivot, sc, &phase, &s,
                                       o->time_limit - t + (top ? top_left : 0.0), &dt)) !=
                PD_OK) {
                pd_drop_failed(out, PD_STAGE_CONTACT_PHASE, st);
                break;
            }
            if (top) {
                double spun = fmin(dt, top_left);
                top_left -= spun;
                run.time_limit += spun;
            }
            t += dt;
            pd_drop_trace_state(m, o, g, index, t, &s, "phase");
            phase_ok = 0;
            if (t >= o->time_limit) {
                out->end = PD_END_TIME_LIMIT;
                break;
            }
            continue;
        }
        /* Touching but not approaching: separating, or resting. Nothing
         * changed the motion, so s goes on along f. When every touching
         * contact leaves the floor faster than resting contact falls onto
         * it, the step is only as long as lifting them clear of the contact
         * tolerance takes: a full rest step would pass over whatever else
         * lands meanwhile (a face's other corners after its first one
         * rebounds), which then starts below the floor. */
        phase_ok = 1;
        if (!plan_if_stale(m->body, &s, g, &f, &f_at, 1, out))
            break;
        double dt = dt_rest, rise = touching_rise(m->body, &s, w->contacts, nc);
        if (rise > w->settle.v_rest)
            dt = fmin(dt, 2.0 * PD_TOL_CONTACT_REL * m->body->size / rise);
        /* Nor long enough for any vertex to sink further than
         * PD_REST_SINK_REL below the floor: the step is blind to vertices
         * other than the touching ones. */
        dt = turn_step(m->body, &s, f.wmax, fabs(s.v.z), PD_REST_SINK_REL * m->body->size, dt);
        /* Nor long enough for the turn to carry a vertex deeper, beyond the
         * centre's fall, than the kinetic energy can pay for lifting the part
         * back (lift_onto_floor), or than the outcome test allows for
         * (PD_REST_TURN_REL): lifted partly for free, a slowly rocking part
         * gained height every step and never settled below a low barrier. */
        double payable = fmax(energy_height(m->body, &s, g) - s.x.z, w->settle.margin);
        dt = turn_step(m->body, &s, f.wmax, 0.0, payable, dt);
        f_at += dt;
        rest_from = s.x.z;
        if ((st = pd_flight_eval(&f, f_at, &s)) != PD_OK) {
            pd_drop_failed(out, PD_STAGE_FLIGHT, st);
            break;
        }
        t += dt;
        pd_drop_trace_state(m, o, g, index, t, &s, "flight");
        if (t >= o->time_limit) {
            out->end = PD_END_TIME_LIMIT;
            break;
        }
    }
    out->time = t;
    if (out->end == PD_END_SETTLED)
        pd_drop_trace_state(m, o, g, index, t, &s, "end");
}
