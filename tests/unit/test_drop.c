/* test_drop.c: single drops and collisions: closed forms of the multi-contact
 * scheme, energy never gained, drops that must end on a known face. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "sim/drop.h"
#include "drop_fixture.h"
#include "dynamics/flight.h"
#include "posedrop/posedrop.h"
#include "base/quat.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

static void test_flat_landing(void)
{
    /* A box landing flat on a face, no spin, frictionless: by symmetry the
     * impulse goes through the face's centre below the centre of mass, so it
     * rebounds at e times the approach speed and does not turn. With friction
     * and a sideways speed it turns, but the normal rebound is the same. */
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.0);
    if (!b)
        return;
    int contacts[64];
    int nc = lowest_vertices(b, quat_identity(), contacts);
    CHECK_INT(nc, 4);
    const double es[] = {0.0, 0.3, 1.0};
    for (int i = 0; i < 3; i++) {
        sc.restitution = es[i];
        pd_state s = {v3(0, 0, 0.1), quat_identity(), v3(0, 0, -1.5), v3(0, 0, 0)};
        int impacts = 0;
        long gain = 0, fb = 0;
        CHECK_STATUS(pd_drop_collide(fx.model, fx.work, &sc, &s, contacts, nc, &impacts, &gain, &fb),
                     PD_OK);
        CHECK_NEAR(s.v.z, 1.5 * es[i], 1e-12, "Poisson rebound, closed form, round-off");
        CHECK_NEAR(v3_norm(s.w), 0.0, 1e-9, "no spin from a centred impulse, round-off");
        CHECK_INT(impacts, 1);
    }
    sc.mu = 0.3;
    sc.restitution = 0.3;
    pd_state s = {v3(0, 0, 0.1), quat_identity(), v3(0.4, 0, -1.5), v3(0, 0, 0)};
    double k0 = kinetic_energy(b, &s);
    int impacts = 0;
    long gain = 0, fb = 0;
    CHECK_STATUS(pd_drop_collide(fx.model, fx.work, &sc, &s, contacts, nc, &impacts, &gain, &fb),
                 PD_OK);
    /* After the rounds no contact approaches any more. */
    pd_vec3 ww = quat_rotate(s.q, s.w);
    double worst = 1e300;
    for (int i = 0; i < nc; i++)
        worst = fmin(worst, s.v.z + v3_cross(ww, quat_rotate(s.q, b->verts[contacts[i]])).z);
    CHECK(worst >= -1e-9);
    CHECK(kinetic_energy(b, &s) <= k0);
    drop_teardown(&fx);
}

static void test_energy_never_gained(void)
{
    /* 2000 random single-vertex impacts of an asymmetric box: kinetic energy
     * never rises (the energetic law stands in for Poisson's where it would). */
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    test_rng rng = {2718};
    int rises = 0, applied = 0;
    long gain = 0, fb = 0;
    for (int t = 0; t < 2000; t++) {
        double r[3][3];
        rng_rotation(&rng, r);
        pd_quat q = quat_normalize(quat_from_matrix(CR(r)));
        int contacts[64], nc = lowest_vertices(b, q, contacts);
        sc.mu = rng_range(&rng, 0.0, 2.0);
        sc.restitution = rng_range(&rng, 0.0, 1.0);
        pd_state s = {v3(0, 0, 0.1), q, v3_scale(rng_unit_vector(&rng), 2.0),
                      v3_scale(rng_unit_vector(&rng), 50.0)};
        s.v.z = -fabs(s.v.z) - 0.1;
        double k0 = kinetic_energy(b, &s);
        int impacts = 0;
        if (pd_drop_collide(fx.model, fx.work, &sc, &s, contacts, nc, &impacts, &gain, &fb) != PD_OK)
            continue;
        applied += impacts > 0;
        rises += kinetic_energy(b, &s) > k0 * (1 + 1e-12);
    }
    CHECK(applied > 1000);
    CHECK_INT(rises, 0);
    drop_teardown(&fx);
}

static void test_resting_drops(void)
{
    /* A 1 x 2 x 3 cm box released resting on each face from 1 mm, without
     * vibration or belt, ends on that face in every drop. */
    pd_scene sc;
    pd_scene_default(&sc);
    sc.height = 1e-3;
    sc.vibration = 0.0;
    sc.belt_speed = 0.0;
    drop_fixture fx;
    if (!drop_setup(&fx, mesh_box(0.01, 0.02, 0.03), &sc))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    int k = fx.poses->nposes, wrong = 0;
    CHECK_INT(k, 6);
    double *cdf = calloc((size_t)k, sizeof *cdf);
    for (int pose = 0; pose < k; pose++) {
        for (int i = 0; i < k; i++)
            cdf[i] = i >= pose ? 1.0 : 0.0;
        for (long d = 0; d < 10; d++) {
            pd_trial t;
            long gain = 0, fb = 0;
            pd_drop_run(fx.model, fx.work, &sc, &o, d, cdf, &t, &gain, &fb);
            wrong += t.end != PD_END_SETTLED || t.pose != pose;
        }
    }
    CHECK_INT(wrong, 0);
    free(cdf);

    /* A nearly elastic bounce would be Zeno; it still ends, on the same face. */
    sc.restitution = 0.95;
    pd_trial t;
    long gain = 0, fb = 0;
    double first[6] = {1, 1, 1, 1, 1, 1};
    pd_drop_run(fx.model, fx.work, &sc, &o, 0, first, &t, &gain, &fb);
    CHECK(t.end == PD_END_SETTLED && t.pose == 0);
    drop_teardown(&fx);
}

static void test_limits(void)
{
    /* Elastic and frictionless: energy never falls below a barrier, so every
     * drop runs into the time limit and is never classified. */
    pd_scene sc;
    pd_scene_default(&sc);
    sc.mu = 0.0;
    sc.restitution = 1.0;
    drop_fixture fx;
    if (!drop_setup(&fx, mesh_box(0.01, 0.02, 0.03), &sc))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.time_limit = 0.3;
    int classified = 0;
    for (long d = 0; d < 5; d++) {
        pd_trial t;
        long gain = 0, fb = 0;
        pd_drop_run(fx.model, fx.work, &sc, &o, d, NULL, &t, &gain, &fb);
        classified += t.end == PD_END_SETTLED || t.pose >= 0;
        CHECK(t.end == PD_END_TIME_LIMIT || t.end == PD_END_COLLISION_LIMIT);
    }
    CHECK_INT(classified, 0);
    drop_teardown(&fx);
}

/* A cube landing 1.5 deg off flat at the speed of a 0.12 m fall. Rigid
 * (contact_time 0), its first corner is struck alone and the impulse, far off
 * the centre of mass, sets it spinning at ~1.4 v / a (here ~200 rad/s),
 * which turns it over; with a window spanning the face's arrival (0.27 mm
 * at 1.5 m/s: 0.2 ms) the four corners are struck as one, near the face's
 * centre, and it barely turns. */
static void test_impact_window(void)
{
    pd_scene sc;
    drop_fixture fx;
    pd_scene_default(&sc);
    if (!drop_setup(&fx, mesh_box(0.01, 0.01, 0.01), &sc))
        return;
    const pd_body *b = (fx.model)->body;
    pd_quat q = quat_axis_angle(v3_unit(v3(1.0, 0.4, 0.0)), 1.5 * M_PI / 180.0);
    double spin[2];
    int ncs[2];
    for (int k = 0; k < 2; k++) {
        sc.contact_time = k ? 3e-4 : 0.0;
        int contacts[64];
        pd_state s = {v3(0, 0, 0.01), q, v3(0, 0, -1.53), v3(0, 0, 0)};
        pd_flight f;
        pd_impact imp;
        CHECK_STATUS(pd_flight_plan(b, &s, sc.gravity, &f), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &f, 1.0, sc.contact_time, contacts, 64, &imp), PD_OK);
        CHECK_STATUS(pd_flight_eval(&f, imp.t, &s), PD_OK);
        int impacts = 0;
        long gain = 0, fb = 0;
        CHECK_STATUS(pd_drop_collide(fx.model, fx.work, &sc, &s, contacts, imp.ncontacts, &impacts,
                                     &gain, &fb), PD_OK);
        ncs[k] = imp.ncontacts;
        spin[k] = v3_norm(s.w);
    }
    CHECK_INT(ncs[0], 1);
    CHECK_INT(ncs[1], 4);
    CHECK(spin[0] > 100.0);
    CHECK(spin[1] < 0.1 * spin[0]);
    pd_note("drop: cube landing 1.5 deg off flat: spin %.1f rad/s rigid, %.1f rad/s with a 0.3 ms window\n",
           spin[0], spin[1]);
    drop_teardown(&fx);
}

void suite_drop(void)
{
    test_impact_window();
    test_flat_landing();
    test_energy_never_gained();
    test_resting_drops();
    test_limits();
}
