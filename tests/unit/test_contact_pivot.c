/* test_contact_pivot.c: two sticking contacts turning about their edge as
 * one angle: the forces as the phase's own solve gives them, and the same
 * motion, events and energy as the thirteen-unknown phase, on random edge
 * pivots of a box and a coin. */
#include <math.h>
#include "check.h"
#include "contact/contact_phase.h"
#include "contact/contact_pivot.h"
#include "drop_fixture.h"
#include "contact/contact_tol.h"
#include "base/quat.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

static const double G = 9.81;

/* A state of body b lying on a random hull edge, contacts[0..2), with
 * every other vertex above it by more than 1e-3 L, turning at up to 3 per
 * sqrt(L/g) about the edge, its contacts at rest; 0 if no such edge was
 * drawn. */
static int random_pivot(const pd_body *b, test_rng *rng, pd_state *s, int contacts[2])
{
    for (int tries = 0; tries < 1000; tries++) {
        int v = (int)(rng_uniform(rng) * b->nverts);
        int deg = b->adj_start[v + 1] - b->adj_start[v];
        int w = b->adj[b->adj_start[v] + (int)(rng_uniform(rng) * deg)];
        pd_vec3 e = v3_unit(v3_sub(b->verts[w], b->verts[v]));
        pd_vec3 n = rng_unit_vector(rng); /* down, body frame */
        n = v3_unit(v3_sub(n, v3_scale(e, v3_dot(n, e))));
        double low = v3_dot(n, b->verts[v]), gap = HUGE_VAL;
        for (int i = 0; i < b->nverts; i++)
            if (i != v && i != w)
                gap = fmin(gap, low - v3_dot(n, b->verts[i]));
        if (!(gap > 1e-3 * b->size))
            continue;
        /* The turn taking n to -z, then a random turn about z. */
        pd_quat q = quat_onto_down(n);
        q = quat_normalize(quat_mul(quat_axis_angle(v3(0, 0, 1), rng_range(rng, 0, 2 * M_PI)), q));
        pd_vec3 r0 = quat_rotate(q, b->verts[v]), ew = quat_rotate(q, e);
        double rate = rng_range(rng, -3.0, 3.0) / sqrt(b->size / G);
        *s = (pd_state){v3(0, 0, -r0.z), q, v3_scale(v3_cross(ew, v3_neg(r0)), rate),
                        v3_scale(e, rate)};
        contacts[0] = v, contacts[1] = w;
        return 1;
    }
    return 0;
}

/* The kind of margin that is smallest at s: 0 a normal force, 1 a cone
 * margin (per weight), 2 the lowest other vertex's height (per L). Kinds,
 * not contacts: on a symmetric edge both contacts' margins cross at once. */
static int event_of(const pd_phase *p, const pd_state *s)
{
    const pd_body *b = p->b;
    pd_phase_forces F;
    if (pd_phase_forces_of(p, s, &F))
        return -1;
    double mg = b->mass * G, g[5], floor_z = HUGE_VAL;
    for (int i = 0; i < 2; i++) {
        g[i] = F.fn[i] / mg, g[2 + i] = F.cone[i] / mg;
        floor_z = fmin(floor_z, s->x.z + quat_rotate(s->q, b->verts[p->v[i]]).z);
    }
    g[4] = HUGE_VAL;
    for (int i = 0; i < b->nverts; i++)
        if (i != p->v[0] && i != p->v[1])
            g[4] = fmin(g[4], (s->x.z + quat_rotate(s->q, b->verts[i]).z - floor_z) / b->size);
    int k = 0;
    for (int i = 1; i < 5; i++)
        if (g[i] < g[k])
            k = i;
    return k / 2;
}

/* At random angles and rates of random edge pivots, the closed-form forces
 * against the phase's least-norm solve: equal to its round-off, 1e-9 of
 * the scale (test_contact_phase.c: the normal equations square K's
 * condition). */
static void check_forces(const pd_body *b, double mu, test_rng *rng)
{
    double worst = 0.0;
    int n = 0, contacts[2];
    pd_state s0;
    pd_phase p;
    pd_pivot pv;
    for (int k = 0; k < 200; k++) {
        if (!random_pivot(b, rng, &s0, contacts))
            continue;
        pd_phase_init(&p, b, G, mu, &s0, contacts, 2, HUGE_VAL);
        if (!pd_pivot_init(&pv, &p, &s0))
            continue;
        double T = sqrt(b->size / G), a = rng_range(rng, -1.0, 1.0), w = rng_range(rng, -5, 5) / T;
        pd_state s;
        pd_phase_forces A, B;
        pd_pivot_state(&pv, a, w, &s, &A);
        if (pd_phase_forces_of(&p, &s, &B))
            continue;
        n++;
        double acc = G + w * w * b->size, force = b->mass * acc;
        double d = fmax(v3_dist(A.acc, B.acc) / acc, v3_dist(A.wdot, B.wdot) * b->size / acc);
        for (int i = 0; i < 2; i++)
            d = fmax(d, fmax(fabs(A.fn[i] - B.fn[i]), fabs(A.cone[i] - B.cone[i])) / force);
        /* the contacts stay put: the state is a rotation about the edge */
        for (int i = 0; i < 2; i++) {
            pd_vec3 c0 = v3_add(s0.x, quat_rotate(s0.q, b->verts[contacts[i]]));
            pd_vec3 c1 = v3_add(s.x, quat_rotate(s.q, b->verts[contacts[i]]));
            d = fmax(d, v3_dist(c0, c1) / b->size);
        }
        worst = fmax(worst, d);
    }
    CHECK(n >= 100);
    CHECK_NEAR(worst, 0.0, 1e-9, "round-off of the least-norm solve");
}

/* Random edge pivots run as a pivot (in closed form, contact_pivot.c) and
 * in full (13 unknowns, rkck at a thousandth of PD_TOL_PHASE_ODE_REL, so
 * that its error is far below the phase's own): they end at the same
 * event (the same margin smallest), within the event tolerance of each
 * other plus the integration's error, 1e-7 sqrt(L/g); run again to just
 * short of the earlier end, they agree to the full motion's accumulated
 * error, a hundred of its steps' local error at most (1e-9); and the
 * pivot's energy is constant to round-off (1e-13 m g L). Measured (box;
 * coin): end times 2.5e-8; 2.6e-8 sqrt(L/g) apart, x 3.0e-11; 2.8e-11 L,
 * v 3.1e-11; 1.7e-11 sqrt(g L), q 2.3e-11; 2.4e-11, w 7.7e-11; 5.5e-11
 * per sqrt(L/g), energy 1.9e-11; 1.7e-11 m g L; the pivot's energy drift
 * 4.3e-16; 3.2e-16 m g L (the integrated pivot's, at
 * PD_TOL_PHASE_ODE_REL, was 6.1e-9; 4.4e-9). */
static void check_motion(drop_fixture *fx, pd_scene *sc, test_rng *rng)
{
    const pd_body *b = (fx->model)->body;
    double L = b->size, T = sqrt(L / G), mgL = b->mass * G * L;
    double tol = 100.0 * 1e-3 * PD_TOL_PHASE_ODE_REL, t_max = 2.0 * T;
    pd_ode *ode = pd_contact_phase_ode_alloc_tol(1e-3), *pivot = pd_contact_pivot_ode_alloc();
    int events = 0, compared = 0, other_event = 0, hint = 0, pose;
    double dt = 0.0, drift = 0.0;
    state_gap gap = {0};
    for (int k = 0; k < 300; k++) {
        pd_state s;
        int contacts[2];
        if (!random_pivot(b, rng, &s, contacts))
            continue;
        pd_phase phase;
        if (!pd_contact_phase_start(&fx->model->settle, sc, &s, contacts, 2, &phase) ||
            phase.mode[0] != PD_PHASE_STICK || phase.mode[1] != PD_PHASE_STICK)
            continue;
        pd_state a = s, f = s;
        double ta, tf;
        if (pd_contact_phase(&fx->model->settle, ode, pivot, sc, &phase, &a, t_max, &ta) != PD_OK ||
            pd_contact_phase(&fx->model->settle, ode, NULL, sc, &phase, &f, t_max, &tf) != PD_OK)
            continue;
        drift = fmax(drift, fabs(total_energy(b, G, &a) - total_energy(b, G, &s)) / mgL);
        if (ta < t_max && tf < t_max && pd_settle_decided(&(fx->model)->settle, &a, G, &hint, &pose) <= 0 &&
            pd_settle_decided(&(fx->model)->settle, &f, G, &hint, &pose) <= 0) {
            pd_phase mapped = phase;
            pd_phase_map(&mapped);
            events++;
            int ea = event_of(&mapped, &a);
            other_event += ea < 0 || ea != event_of(&mapped, &f); /* a failed model is no match */
            dt = fmax(dt, fabs(ta - tf) / T);
        }
        /* Both again, to short of the earlier end. */
        double t_c = 0.9 * fmin(ta, tf);
        a = s, f = s;
        if (!(t_c > 0.0) ||
            pd_contact_phase(&fx->model->settle, ode, pivot, sc, &phase, &a, t_c, &ta) != PD_OK ||
            pd_contact_phase(&fx->model->settle, ode, NULL, sc, &phase, &f, t_c, &tf) != PD_OK ||
            ta < t_c * (1.0 - 1e-12) || tf < t_c * (1.0 - 1e-12))
            continue;
        compared++;
        state_gap_add(&gap, b, G, &a, &f);
    }
    CHECK(events >= 30);
    CHECK(compared >= 50);
    CHECK_INT(other_event, 0);
    CHECK_NEAR(dt, 0.0, PD_TOL_PHASE_EVENT_REL + 1e-7, "end times per sqrt(L/g)");
    state_gap_check(&gap, tol);
    CHECK_NEAR(drift, 0.0, 1e-13, "the pivot's energy over a phase: round-off");
    pd_note("contact_pivot: %d events, %d compared: t %.1e x %.1e v %.1e q %.1e w %.1e E %.1e, "
           "pivot energy drift %.1e m g L\n",
           events, compared, dt, gap.x, gap.v, gap.q, gap.w, gap.E, drift);
    pd_ode_free(pivot);
    pd_ode_free(ode);
}

void suite_contact_pivot(void)
{
    test_rng rng = {211};
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 1.0);
    if (b) {
        check_forces(b, sc.mu, &rng);
        check_motion(&fx, &sc, &rng);
        drop_teardown(&fx);
    }
    pd_scene_default(&sc);
    sc.mu = 1.0;
    if (drop_setup(&fx, mesh_prism(32, 0.01, 0.01), &sc)) {
        b = (fx.model)->body;
        check_forces(b, sc.mu, &rng);
        check_motion(&fx, &sc, &rng);
        drop_teardown(&fx);
    }
}
