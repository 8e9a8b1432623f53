/* test_engine_extreme.c: every engine (impulse, ODE, Bullet) on scenes at
 * the edges: a 1 m x 1 cm x 1 cm rod, a 1 x 1 x 0.01 mm flake and a 1 mm
 * cube, under friction 10, restitution 0, restitution 1, and restitution 1
 * without friction (which conserves energy, so the impulse simulator can
 * never settle it: it must end at its limits). Each drop must end with a
 * finite record, within the run's limits (its simulated time and
 * collisions are its work), and never as a failure. A few drops each and a
 * short time limit, so the sanitizer build stays quick. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "engine_steps.h"
#include "posedrop/bullet.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"

enum { EXTREME_DROPS = 4 };
static const double EXTREME_TIME = 2.0; /* s of simulated time per drop */

typedef struct {
    const char *name;
    double mu, e;
} extreme_scene;

static void run_extreme(const char *part_name, const pd_part *part, const pd_static_result *poses,
                        pd_engine_kind engine, const extreme_scene *es)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.mu = es->mu;
    sc.restitution = es->e;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    o.ndrops = EXTREME_DROPS;
    o.threads = 2;
    o.time_limit = EXTREME_TIME;
    o.keep_trials = 1;
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_sim_run(part, poses, &sc, &o, &r, &d);
    if (st != PD_OK)
        printf("     %s, %s, engine %d: %s\n", part_name, es->name, (int)engine, d.message);
    CHECK_STATUS(st, PD_OK);
    if (!r)
        return;
    CHECK_INT(r->n, o.ndrops);
    /* A stepping engine's steps are bounded by the time limit (the last
     * step may end past it by less than a step); the impulse simulator's
     * events by the time limit and the collision cap, its compliant impacts
     * ending on their own steps, each shorter than a contact duration. */
    double T = sc.contact_time == PD_CONTACT_TIME_AUTO
                   ? pd_contact_time_auto(pd_contact_time_auto_size(part))
                   : sc.contact_time;
    double dt = engine == PD_ENGINE_IMPULSE ? T
                : engine == PD_ENGINE_ODE   ? 1e-3
                                            : 1.0 / 960.0;
    long bad = 0, failed = 0, unsettled = 0;
    for (long i = 0; i < r->n; i++) {
        const pd_trial *t = &r->trials[i];
        int finite = isfinite(t->time) && isfinite(t->q0[0]) && isfinite(t->q0[1]) &&
                     isfinite(t->q0[2]) && isfinite(t->q0[3]);
        bad += !finite || !(t->time <= o.time_limit + dt) || t->collisions > o.max_collisions ||
               (t->end == PD_END_SETTLED) != (t->pose >= 0);
        failed += t->end == PD_END_FAILED;
        unsettled += t->end != PD_END_SETTLED;
    }
    if (bad || failed)
        printf("     %s, %s, engine %d: %ld records out of bounds, %ld failed\n", part_name,
               es->name, (int)engine, bad, failed);
    CHECK_INT(bad, 0);
    CHECK_INT(failed, 0);
    CHECK_INT(r->unsettled, unsettled);
    for (int k = 0; k < r->nposes; k++)
        CHECK(isfinite(r->p[k]) && isfinite(r->ci_lo[k]) && isfinite(r->ci_hi[k]));
    /* Energy conserved: the impulse simulator has nothing to settle with. */
    if (engine == PD_ENGINE_IMPULSE && es->e == 1.0 && es->mu == 0.0)
        CHECK_INT(r->unsettled, r->n);
    pd_sim_result_free(r);
}

void suite_engine_extreme(void)
{
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    const char *names[3] = {"1 m rod", "0.01 mm flake", "1 mm cube"};
    pd_mesh *meshes[3] = {mesh_box(1.0, 0.01, 0.01), mesh_box(0.001, 0.001, 0.00001),
                          mesh_box(0.001, 0.001, 0.001)};
    const extreme_scene scenes[4] = {
        {"mu 10", 10.0, 0.3}, {"e 0", 0.3, 0.0}, {"e 1", 0.3, 1.0}, {"e 1, mu 0", 0.0, 1.0}};
    const pd_engine_kind engines[3] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
    for (int p = 0; p < 3; p++) {
        pd_part *part = NULL;
        pd_static_result *poses = NULL;
        int ok = meshes[p] && pd_part_build(meshes[p], NULL, &part, NULL) == PD_OK &&
                 pd_static_estimate(part, NULL, &poses, NULL) == PD_OK;
        pd_mesh_free(meshes[p]);
        CHECK(ok);
        for (int s = 0; ok && s < 4; s++)
            for (int e = 0; e < 3; e++)
                run_extreme(names[p], part, poses, engines[e], &scenes[s]);
        pd_static_result_free(poses);
        pd_part_free(part);
    }
}
