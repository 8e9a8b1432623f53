/* test_engine_contact.c: the scene's contact (contact_time T > 0,
 * restitution e) in the stepping engines: the spring-dashpot of
 * pd_engine_contact_law against its closed form, then ODE and Bullet
 * striking the floor with one corner and rebounding with e after a contact
 * of T, to first order in the step. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "dynamics/body.h"
#include "engines/engine.h"
#include "engines/engine_contact.h"
#include "posedrop/posedrop.h"
#include "base/quat.h"
#include "base/vec3.h"
#include "shapes.h"
#include "suites.h"

static const double RESTITUTIONS[] = {0.01, 0.05, 0.3, 0.6, 0.9, 1.0};

/* Contact duration times omega of a push-only spring-dashpot of damping
 * ratio z (engine.h), written here from its two branches again. */
static double push_only_duration(double z)
{
    if (z < 1.0)
        return (M_PI - 2.0 * asin(z)) / sqrt(1.0 - z * z);
    return z > 1.0 ? 2.0 * log(z + sqrt(z * z - 1.0)) / sqrt(z * z - 1.0) : 2.0;
}

/* The law's omega and zeta give back T and e through the closed forms, to
 * the bisection's round-off (1e-12 relative: 200 halvings of zeta's bracket,
 * and e(zeta)'s slope is of order 1); at e = 1 no damping at all, the
 * undamped half period pi / omega = T. Below PD_ENGINE_E_MIN, e is that. */
static void test_law(void)
{
    const double T = 5e-4;
    for (size_t i = 0; i < sizeof RESTITUTIONS / sizeof RESTITUTIONS[0]; i++) {
        double e = RESTITUTIONS[i], omega, zeta;
        pd_engine_contact_law(T, e, &omega, &zeta);
        double g = push_only_duration(zeta);
        CHECK_REL(g / omega, T, 1e-12, "duration, closed form");
        CHECK_REL(exp(-zeta * g), e, 1e-12, "restitution, closed form");
    }
    double omega, zeta;
    pd_engine_contact_law(T, 1.0, &omega, &zeta);
    CHECK_INT(zeta == 0.0, 1);
    CHECK_REL(omega, M_PI / T, 1e-15, "undamped half period");
    pd_engine_contact_law(T, 0.0, &omega, &zeta);
    CHECK_REL(exp(-zeta * push_only_duration(zeta)), PD_ENGINE_E_MIN, 1e-12, "e clamped");
}

/* The shortest rotation taking unit a onto unit b (not opposite). */
static pd_quat turn_onto(pd_vec3 a, pd_vec3 b)
{
    pd_vec3 c = v3_cross(a, b);
    return quat_axis_angle(v3_unit(c), atan2(v3_norm(c), v3_dot(a, b)));
}

/* The 1 cm cube and its body; 0 (a check counted) on failure. */
static int cube(pd_part **part, pd_body **b)
{
    pd_mesh *m = mesh_box(0.01, 0.01, 0.01);
    *part = NULL;
    *b = NULL;
    int ok = m && pd_part_build(m, NULL, part, NULL) == PD_OK &&
             pd_body_build(*part, b, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    return ok;
}

typedef struct {
    double e;        /* rebound speed over approach speed */
    double duration; /* s: first to last step whose velocity changed */
} corner_impact;

/* A 1 cm cube without gravity strikes the floor with one corner straight
 * below its centre of mass (so the corner's effective mass is the cube's and
 * no spin arises) at 0.5 m/s, in steps of dt. */
static corner_impact strike(const pd_engine *eng, const pd_body *b, const pd_hull *h,
                            const pd_scene *sc, double dt)
{
    corner_impact r = {NAN, NAN};
    double v = 0.5, far = 0.0;
    int c = 0;
    for (int i = 0; i < b->nverts; i++)
        if (v3_norm(b->verts[i]) > far) {
            far = v3_norm(b->verts[i]);
            c = i;
        }
    pd_engine_world *w = eng->world_alloc(b, h, sc, dt);
    CHECK(w != NULL);
    if (!w)
        return r;
    pd_state s = {v3(0, 0, far + 0.5 * v * dt), turn_onto(v3_unit(b->verts[c]), v3(0, 0, -1)),
                  v3(0, 0, -v), v3(0, 0, 0)};
    CHECK_STATUS(eng->reset(w, &s), PD_OK);
    long first = -1, last = -1, after = 0;
    /* The contact lasts at most a few hundred steps; 1e5 bound the loop if
     * it never ended. */
    for (long k = 0; k < 100000 && after < 10; k++) {
        double vz = s.v.z;
        if (eng->step(w, &s) != PD_OK)
            break;
        if (fabs(s.v.z - vz) > 1e-6 * v) {
            if (first < 0)
                first = k;
            last = k;
        } else if (first >= 0)
            after++;
    }
    if (first >= 0 && after >= 10) {
        r.e = s.v.z / v;
        r.duration = (double)(last - first + 1) * dt;
    }
    eng->world_free(w);
    return r;
}

/* Both engines, three restitutions, at T / 200 and T / 400. Each engine
 * steps the spring-dashpot implicitly (erp and cfm are backward Euler's),
 * which loses e g^2 / 2 h / T of the rebound over the contact (g = omega T,
 * at most pi): 4.2 h / T at e = 0.9, the worst here; so |e' - e| <= 5 h / T.
 * The duration is counted in whole steps, one at each end, and is first
 * order too (measured 3 h at e = 0.05): |T' - T| <= 4 h. Halving the step
 * must move e' toward e (first order: the error about halves). */
static void test_corner_impacts(void)
{
    pd_part *part;
    pd_body *b;
    int ok = cube(&part, &b);
    const pd_engine *engines[2] = {&pd_engine_ode, &pd_engine_bullet};
    const double es[3] = {0.05, 0.3, 0.9};
    for (int k = 0; ok && k < 2; k++)
        for (int j = 0; j < 3; j++) {
            pd_scene sc;
            pd_scene_default(&sc);
            sc.gravity = 0.0;
            sc.contact_time = 5e-4;
            sc.restitution = es[j];
            corner_impact coarse = strike(engines[k], b, part->hull, &sc, sc.contact_time / 200);
            corner_impact fine = strike(engines[k], b, part->hull, &sc, sc.contact_time / 400);
            CHECK_NEAR(coarse.e, es[j], 5.0 / 200.0, "first order, 5 h / T");
            CHECK_NEAR(fine.e, es[j], 5.0 / 400.0, "first order, 5 h / T");
            CHECK(fabs(fine.e - es[j]) < 0.75 * fabs(coarse.e - es[j]));
            CHECK_NEAR(coarse.duration, sc.contact_time, 4.0 * sc.contact_time / 200.0,
                       "whole steps, first order: 4 h");
            CHECK_NEAR(fine.duration, sc.contact_time, 4.0 * sc.contact_time / 400.0,
                       "whole steps, first order: 4 h");
        }
    pd_body_free(b);
    pd_part_free(part);
}

/* A contact shorter than PD_ENGINE_CONTACT_STEPS steps is the engine's
 * own: the strike at T / 2 per step gives the bytes the same strike gives
 * with contact_time 0. */
static void test_unresolved(void)
{
    pd_part *part;
    pd_body *b;
    int ok = cube(&part, &b);
    const pd_engine *engines[2] = {&pd_engine_ode, &pd_engine_bullet};
    for (int k = 0; ok && k < 2; k++) {
        pd_scene sc;
        pd_scene_default(&sc);
        sc.gravity = 0.0;
        sc.contact_time = 5e-4;
        corner_impact a = strike(engines[k], b, part->hull, &sc, 2.5e-4);
        sc.contact_time = 0.0;
        corner_impact r = strike(engines[k], b, part->hull, &sc, 2.5e-4);
        CHECK(isfinite(a.e) && memcmp(&a, &r, sizeof a) == 0);
    }
    pd_body_free(b);
    pd_part_free(part);
}

void suite_engine_contact(void)
{
    test_law();
    test_corner_impacts();
    test_unresolved();
}
