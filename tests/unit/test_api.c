/* test_api.c: the library's contracts with a program: its version, the
 * engines a program can ask for (Bullet only once registered), and
 * pd_sim_run refusing impossible scenes and options with a status that names
 * the field, before any drop runs.
 *
 * Runs before every other suite that uses Bullet (suites.h), so the first
 * checks see an unregistered Bullet, as a C program that never links
 * libposedrop-bullet does. */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include "check.h"
#include "engines/engine.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"

static void test_version(void)
{
    CHECK(strcmp(pd_version(), PD_VERSION_STRING) == 0);
    int major = -1, minor = -1, patch = -1, end = 0;
    CHECK_INT(sscanf(pd_version(), "%d.%d.%d%n", &major, &minor, &patch, &end), 3);
    CHECK_INT(end, (int)strlen(pd_version()));
    CHECK_INT(major, PD_VERSION_MAJOR);
    CHECK_INT(minor, PD_VERSION_MINOR);
    CHECK_INT(patch, PD_VERSION_PATCH);
    CHECK_INT(PD_VERSION_NUMBER, major * 10000 + minor * 100 + patch);
}

typedef struct {
    pd_part *part;
    pd_static_result *poses;
} fixture;

/* The 1 x 2 x 3 cm box. */
static int setup(fixture *f)
{
    memset(f, 0, sizeof *f);
    pd_mesh *m = mesh_box(0.01, 0.02, 0.03);
    int ok = m && pd_part_build(m, NULL, &f->part, NULL) == PD_OK &&
             pd_static_estimate(f->part, NULL, &f->poses, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    return ok;
}

/* pd_sim_run must fail with want, leave *result as it was and name the
 * field in its message. */
static void expect_refused(const fixture *f, const pd_scene *sc, const pd_sim_options *o,
                           pd_status want, const char *field)
{
    pd_sim_result untouched, *r = &untouched;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_sim_run(f->part, f->poses, sc, o, &r, &d);
    CHECK_STATUS(st, want);
    CHECK(r == &untouched);
    if (!strstr(d.message, field))
        printf("     expected '%s' in the message: %s\n", field, d.message);
    CHECK(strstr(d.message, field) != NULL);
}

static void test_engines(const fixture *f)
{
    CHECK_INT(pd_engine_available(PD_ENGINE_IMPULSE), 1);
    CHECK_INT(pd_engine_available(PD_ENGINE_ODE), 1);
    CHECK_INT(pd_engine_available((pd_engine_kind)7), 0);
    /* Not registered yet: a clear status, not a crash. */
    CHECK_INT(pd_engine_available(PD_ENGINE_BULLET), 0);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = PD_ENGINE_BULLET;
    expect_refused(f, NULL, &o, PD_ERR_UNAVAILABLE, "pd_bullet_register");
    CHECK(pd_status_is_input_error(PD_ERR_UNAVAILABLE));

    /* Only Bullet registers, only with the table of this very version. */
    CHECK_STATUS(pd_engine_register(PD_ENGINE_BULLET, &pd_engine_bullet, "0.0.0"),
                 PD_ERR_UNAVAILABLE);
    CHECK_STATUS(pd_engine_register(PD_ENGINE_ODE, &pd_engine_bullet, PD_VERSION_STRING),
                 PD_ERR_USAGE);
    CHECK_STATUS(pd_engine_register(PD_ENGINE_BULLET, NULL, PD_VERSION_STRING), PD_ERR_USAGE);
    CHECK_INT(pd_engine_available(PD_ENGINE_BULLET), 0);

    CHECK_STATUS(pd_bullet_register(), PD_OK);
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    CHECK_INT(pd_engine_available(PD_ENGINE_BULLET), 1);
    /* No drops: the run builds its model and Bullet's worlds, and returns. */
    o.ndrops = 0;
    o.threads = 2;
    pd_sim_result *r = NULL;
    CHECK_STATUS(pd_sim_run(f->part, f->poses, NULL, &o, &r, NULL), PD_OK);
    CHECK(r != NULL && r->n == 0 && r->partial == 0);
    pd_sim_result_free(r);
}

static void test_impossible_scenes(const fixture *f)
{
    /* One drop: a refusal comes before any drop whatever ndrops is, and the
     * accepted scenes should cost no time. */
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 1;
    o.threads = 1;
    const struct {
        const char *field;
        size_t at;
        double value;
        pd_status want;
    } bad[] = {
        {"restitution", offsetof(pd_scene, restitution), 3.0, PD_ERR_RANGE},
        {"restitution", offsetof(pd_scene, restitution), -0.1, PD_ERR_RANGE},
        {"restitution", offsetof(pd_scene, restitution), NAN, PD_ERR_NONFINITE},
        {"mu", offsetof(pd_scene, mu), -0.5, PD_ERR_RANGE},
        {"mu", offsetof(pd_scene, mu), 11.0, PD_ERR_RANGE},
        {"mu", offsetof(pd_scene, mu), INFINITY, PD_ERR_NONFINITE},
        {"height", offsetof(pd_scene, height), -0.01, PD_ERR_RANGE},
        {"height", offsetof(pd_scene, height), NAN, PD_ERR_NONFINITE},
        {"height", offsetof(pd_scene, height), 2e3, PD_ERR_RANGE},
        {"belt_speed", offsetof(pd_scene, belt_speed), -2e3, PD_ERR_RANGE},
        {"belt_speed", offsetof(pd_scene, belt_speed), -INFINITY, PD_ERR_NONFINITE},
        {"vibration", offsetof(pd_scene, vibration), 4.0, PD_ERR_RANGE},
        {"vibration", offsetof(pd_scene, vibration), -1e-9, PD_ERR_RANGE},
        {"gravity", offsetof(pd_scene, gravity), 0.0, PD_ERR_RANGE},
        {"gravity", offsetof(pd_scene, gravity), -9.81, PD_ERR_RANGE},
        {"contact_time", offsetof(pd_scene, contact_time), -1e-3, PD_ERR_RANGE},
        {"contact_time", offsetof(pd_scene, contact_time), NAN, PD_ERR_NONFINITE},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        pd_scene sc;
        pd_scene_default(&sc);
        *(double *)(void *)((char *)&sc + bad[i].at) = bad[i].value;
        expect_refused(f, &sc, &o, bad[i].want, bad[i].field);
        CHECK_STATUS(pd_scene_check(&sc, NULL), bad[i].want);
    }
    pd_scene sc;
    pd_scene_default(&sc);
    sc.law = (pd_restitution_law)2;
    expect_refused(f, &sc, &o, PD_ERR_RANGE, "restitution_law");
    pd_scene_default(&sc);
    sc.initial = (pd_initial)-1;
    expect_refused(f, &sc, &o, PD_ERR_RANGE, "initial");
    CHECK_STATUS(pd_scene_check(NULL, NULL), PD_ERR_USAGE);

    /* Every value the text form accepts passes the check, the ends of each
     * range included (vibration's 180 degrees is pi after rounding). */
    const char *const ends[][3] = {
        {"height", "0", "1000"},      {"belt_speed", "-1000", "1000"}, {"mu", "0", "10"},
        {"restitution", "0", "1"},    {"vibration", "0", "180"},       {"gravity", "0.001", "1000"},
        {"contact_time", "0", "1"},
    };
    for (size_t i = 0; i < sizeof ends / sizeof ends[0]; i++)
        for (int e = 1; e <= 2; e++) {
            pd_scene_default(&sc);
            CHECK_STATUS(pd_scene_set(&sc, ends[i][0], ends[i][e], NULL), PD_OK);
            CHECK_STATUS(pd_scene_check(&sc, NULL), PD_OK);
        }
    /* The ends of the friction and restitution ranges run. */
    pd_scene_default(&sc);
    sc.mu = 0.0;
    sc.restitution = 1.0;
    pd_sim_result *r = NULL;
    CHECK_STATUS(pd_sim_run(f->part, f->poses, &sc, &o, &r, NULL), PD_OK);
    CHECK(r != NULL && r->n == 1);
    pd_sim_result_free(r);
}

/* Options with one field spoiled by stmt are refused with want, naming it. */
#define REFUSE(stmt, want, field)                                                          \
    do {                                                                                   \
        pd_sim_options o;                                                                  \
        pd_sim_options_default(&o);                                                        \
        stmt;                                                                              \
        expect_refused(f, NULL, &o, want, field);                                          \
    } while (0)

static void test_impossible_options(const fixture *f)
{
    REFUSE(o.ndrops = -1, PD_ERR_USAGE, "ndrops");
    REFUSE(o.threads = -2, PD_ERR_USAGE, "threads");
    REFUSE(o.dt = NAN, PD_ERR_NONFINITE, "dt");
    REFUSE(o.dt = -1e-3, PD_ERR_USAGE, "dt");
    REFUSE(o.dt = 0.5, PD_ERR_USAGE, "dt");
    REFUSE(o.ci_halfwidth = 0.5, PD_ERR_USAGE, "ci_halfwidth");
    REFUSE(o.ci_halfwidth = -0.01, PD_ERR_USAGE, "ci_halfwidth");
    REFUSE(o.ci_halfwidth = NAN, PD_ERR_NONFINITE, "ci_halfwidth");
    REFUSE(o.max_drops = -1, PD_ERR_USAGE, "max_drops");
    REFUSE(o.time_limit = -1, PD_ERR_USAGE, "time_limit");
    REFUSE(o.time_limit = INFINITY, PD_ERR_NONFINITE, "time_limit");
    REFUSE(o.max_collisions = 0, PD_ERR_USAGE, "max_collisions");
    REFUSE(o.keep_trials = 2, PD_ERR_USAGE, "keep_trials");
    REFUSE(o.engine = (pd_engine_kind)3, PD_ERR_USAGE, "engine");
}

void suite_api(void)
{
    test_version();
    fixture f;
    if (!setup(&f))
        return;
    test_engines(&f);
    test_impossible_scenes(&f);
    test_impossible_options(&f);
    pd_static_result_free(f.poses);
    pd_part_free(f.part);
}
