/* test_engine_bullet.c: the Bullet stepping engine through its C interface
 * (engine.h): free flight against the closed form, a box resting on each
 * face at the face's height (the margin trap), landing flat, toppling off an
 * edge to the side the centre of mass leans to, reset and determinism. */
#include <stdlib.h>
#include <string.h>
#include "dynamics/body.h"
#include "check.h"
#include "engines/engine.h"
#include "posedrop/posedrop.h"
#include "engines/engines_tol.h"
#include "engines/engine_contact.h"
#include "base/base_tol.h"
#include "base/quat.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

#define DT (1.0 / 960.0)

/* Bullet here is single precision: a coordinate of size X carries ~6e-8 X
 * per operation, and a few hundred steps accumulate that to ~1e-6 X. */
#define FLOAT_ACC 1e-6

/* A box resting on a face still slides a little under Bullet's iterative
 * friction in single precision: 2.4e-6 m in 1 s measured (6.5e-5 of its size
 * L) on the 1 x 2 x 3 cm box, 1.2e-4 L on the 1 m rod, with the adapter's
 * two friction directions (one direction crept 1.2e-4 m on the box). Bound:
 * 2e-4 L, a creep that no pose decision can see. */
#define REST_CREEP_REL 2e-4

typedef struct {
    pd_part *part;
    pd_body *body;
    pd_scene scene;
    pd_engine_world *w;
} fixture;

static int setup(fixture *fx, double ax, double ay, double az)
{
    memset(fx, 0, sizeof *fx);
    pd_scene_default(&fx->scene);
    /* Bullet's own contact (restitution, penetration recovery), whose margin
     * handling these tests pin to 1% of the margin; the scene's
     * spring-dashpot (contact_time > 0) rests lower by its static
     * compression and is tested in test_engine_contact.c. */
    fx->scene.contact_time = 0.0;
    pd_mesh *mesh = mesh_box(ax, ay, az);
    int ok = mesh && pd_part_build(mesh, NULL, &fx->part, NULL) == PD_OK &&
             pd_body_build(fx->part, &fx->body, NULL) == PD_OK &&
             (fx->w = pd_engine_bullet.world_alloc(fx->body, fx->part->hull, &fx->scene, DT)) !=
                 NULL;
    pd_mesh_free(mesh);
    CHECK(ok);
    return ok;
}

static void teardown(fixture *fx)
{
    pd_engine_bullet.world_free(fx->w);
    pd_body_free(fx->body);
    pd_part_free(fx->part);
}

/* Rotation taking unit a to unit b (by pi about a perpendicular axis when
 * they are opposite). */
static pd_quat quat_between(pd_vec3 a, pd_vec3 b)
{
    pd_vec3 c = v3_cross(a, b);
    double s = v3_norm(c), d = v3_dot(a, b);
    if (s < 1e-12) {
        if (d > 0.0)
            return quat_identity();
        pd_vec3 p = fabs(a.x) < 0.9 ? v3(1, 0, 0) : v3(0, 1, 0);
        return quat_axis_angle(v3_unit(v3_cross(a, p)), M_PI);
    }
    return quat_axis_angle(v3_scale(c, 1.0 / s), atan2(s, d));
}

/* Body orientation (principal -> world) that turns the part-frame direction
 * n_part straight down. */
static pd_quat face_down(const pd_body *b, pd_vec3 n_part)
{
    return quat_mul(quat_between(n_part, v3(0, 0, -1)), b->frame);
}

/* The hull facet whose outward normal points most nearly down in state s,
 * and the angle between them. */
static int facet_down(const fixture *fx, const pd_state *s, double *angle)
{
    const pd_hull *h = fx->part->hull;
    pd_quat part_to_world = quat_mul(s->q, quat_conj(fx->body->frame));
    int best = -1;
    double best_a = 10.0;
    for (int f = 0; f < h->nfacets; f++) {
        double a = v3_angle(quat_rotate(part_to_world, h->normal[f]), v3(0, 0, -1));
        if (a < best_a) {
            best_a = a;
            best = f;
        }
    }
    *angle = best_a;
    return best;
}

/* Height of the centre of mass above facet f's plane. */
static double facet_height(const fixture *fx, int f)
{
    const pd_hull *h = fx->part->hull;
    return h->offset[f] - v3_dot(h->normal[f], fx->part->com);
}

static int run(fixture *fx, pd_state *s, int nsteps)
{
    for (int i = 0; i < nsteps; i++)
        if (pd_engine_bullet.step(fx->w, s) != PD_OK)
            return 0;
    return 1;
}

static pd_vec3 ang_momentum_world(const pd_body *b, const pd_state *s)
{
    pd_vec3 lb = v3(b->moment[0] * s->w.x, b->moment[1] * s->w.y, b->moment[2] * s->w.z);
    return quat_rotate(s->q, lb);
}

static void test_free_flight(void)
{
    fixture fx;
    if (!setup(&fx, 0.01, 0.02, 0.03))
        return;
    const double g = fx.scene.gravity, T = 0.1;
    const int n = 96; /* T / DT */
    pd_state s0 = {v3(0.01, -0.02, 0.1), quat_normalize(quat(0.9, 0.2, -0.3, 0.1)),
                   v3(0.1, -0.2, 0.3), v3(3.0, 20.0, -5.0)};
    pd_state s = s0;
    CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
    CHECK(run(&fx, &s, n));
    /* Symplectic Euler (v += g dt, then x += v dt) is exact for the velocity
     * and lands g dt T / 2 below the parabola after time T. */
    CHECK_NEAR(s.v.z, s0.v.z - g * T, FLOAT_ACC * g * T, "exact velocity, float round-off");
    CHECK_NEAR(s.x.x, s0.x.x + s0.v.x * T, FLOAT_ACC, "x + v t, float round-off");
    CHECK_NEAR(s.x.y, s0.x.y + s0.v.y * T, FLOAT_ACC, "x + v t, float round-off");
    CHECK_NEAR(s.x.z, s0.x.z + s0.v.z * T - 0.5 * g * T * T, 0.5 * g * DT * T + FLOAT_ACC,
               "parabola, symplectic Euler lag g dt T / 2");
    /* Torque-free: the world angular momentum is constant in truth. The
     * adapter's first-order (backward Euler) gyroscopic step errs by about
     * (|w| dt)^2 / 2 of |L| per step, so after T / dt steps by
     * |w|^2 dt T / 2: 2.3e-2 for |w| = 21 rad/s about the unstable middle
     * axis (measured 3e-3). */
    pd_vec3 L0 = ang_momentum_world(fx.body, &s0), L = ang_momentum_world(fx.body, &s);
    double wn = v3_norm(s0.w);
    CHECK_NEAR(v3_dist(L, L0) / v3_norm(L0), 0.0, 0.5 * wn * wn * DT * T,
               "first-order gyroscopic step: |w|^2 dt T / 2");
    teardown(&fx);
}

static void test_reset_read_back(void)
{
    /* Spin about a principal axis in free flight: one step must hand back the
     * state it was given, moved by exactly one step of gravity. */
    fixture fx;
    if (!setup(&fx, 0.01, 0.02, 0.03))
        return;
    pd_state s0 = {v3(0.0, 0.0, 0.2), quat_identity(), v3(0.0, 0.0, 0.0), v3(0.0, 0.0, 5.0)};
    pd_state s;
    CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
    CHECK_STATUS(pd_engine_bullet.step(fx.w, &s), PD_OK);
    double g = fx.scene.gravity;
    CHECK_NEAR(s.v.z, -g * DT, FLOAT_ACC * g * DT, "one step of gravity, float");
    CHECK_NEAR(s.x.z, 0.2 - g * DT * DT, FLOAT_ACC * 0.2, "one step of symplectic Euler, float");
    CHECK_NEAR(v3_dist(s.w, s0.w), 0.0, FLOAT_ACC * 5.0, "principal spin is steady, float");
    pd_quat turned = quat_mul(s0.q, quat_exp(v3_scale(s0.w, DT)));
    CHECK_NEAR(fabs(quat_mul(quat_conj(turned), s.q).w), 1.0, FLOAT_ACC,
               "turned by w dt, float");
    teardown(&fx);
}

/* The trap: with Bullet's margin outside the hull the box floats by the
 * margin (and by 0.04 m with the default). With the floor lowered by it the
 * com sits at the face's height; what is left is the solver's steady
 * penetration under g, ~g dt^2, and float round-off. The 1 m x 1 cm x 1 cm
 * rod is the other trap: with Bullet's contact threshold (1 cm for it) the
 * corners of an end face merged into one contact, and the rod rolled off
 * its long faces onto an edge and sank 9 mm into the floor. */
static void test_rest_on_each_face(double ax, double ay, double az)
{
    fixture fx;
    if (!setup(&fx, ax, ay, az))
        return;
    const double side = fmin(ax, fmin(ay, az));
    const pd_hull *h = fx.part->hull;
    CHECK_INT(h->nfacets, 6);
    const double margin = PD_BULLET_MARGIN_REL * fx.body->size;
    double worst_h = 0.0, worst_tilt = 0.0, worst_slide = 0.0;
    for (int f = 0; f < h->nfacets; f++) {
        double hf = facet_height(&fx, f);
        pd_state s0 = {v3(0.0, 0.0, hf), face_down(fx.body, h->normal[f]), v3(0, 0, 0),
                       v3(0, 0, 0)};
        pd_state s = s0;
        CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
        int ok = run(&fx, &s, 960);
        CHECK(ok);
        double a;
        CHECK_INT(facet_down(&fx, &s, &a), f);
        worst_h = fmax(worst_h, fabs(s.x.z - hf));
        worst_tilt = fmax(worst_tilt, a);
        worst_slide = fmax(worst_slide, hypot(s.x.x, s.x.y));
    }
    CHECK_NEAR(worst_h, 0.0, 0.01 * margin, "1% of the margin: floor lowered by it");
    CHECK_NEAR(worst_tilt, 0.0, 0.01 * margin / side, "1% of the margin over the shortest side");
    CHECK_NEAR(worst_slide, 0.0, REST_CREEP_REL * fx.body->size, "friction solver creep");
    teardown(&fx);
}

static void test_flat_from_1mm(void)
{
    fixture fx;
    if (!setup(&fx, 0.01, 0.02, 0.03))
        return;
    const pd_hull *h = fx.part->hull;
    const double margin = PD_BULLET_MARGIN_REL * fx.body->size;
    for (int f = 0; f < h->nfacets; f++) {
        double hf = facet_height(&fx, f);
        pd_state s0 = {v3(0.0, 0.0, hf + 0.001), face_down(fx.body, h->normal[f]), v3(0, 0, 0),
                       v3(0, 0, 0)};
        pd_state s = s0;
        CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
        CHECK(run(&fx, &s, 960));
        double a;
        CHECK_INT(facet_down(&fx, &s, &a), f);
        CHECK_NEAR(s.x.z, hf, 0.01 * margin, "1% of the margin, as at rest");
        CHECK_NEAR(v3_norm(s.v), 0.0, 2.0 * fx.scene.gravity * DT,
                   "at rest: below two steps of gravity");
    }
    teardown(&fx);
}

/* The box stands on its edge between faces -x and -z (part frame), turned
 * about y so its centre of mass is lean radians past the vertical through
 * the edge: positive leans toward +x, over face -z. */
static void test_topple(double lean, pd_vec3 expect_normal)
{
    fixture fx;
    if (!setup(&fx, 0.01, 0.02, 0.03))
        return;
    /* From the edge (-0.005, ., -0.015) to the com (the origin): balanced
     * when that vector is vertical. */
    pd_vec3 c = v3(0.005, 0.0, 0.015);
    double balance = -atan2(c.x, c.z);
    pd_quat part_to_world = quat_axis_angle(v3(0, 1, 0), balance + lean);
    pd_vec3 cw = quat_rotate(part_to_world, c);
    CHECK_NEAR(cw.x, 0.015811 * sin(lean), 1e-6, "construction");
    pd_state s0 = {v3(0.0, 0.0, cw.z), quat_mul(part_to_world, fx.body->frame), v3(0, 0, 0),
                   v3(0, 0, 0)};
    pd_state s = s0;
    CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
    CHECK(run(&fx, &s, 2 * 960));
    double a;
    int f = facet_down(&fx, &s, &a);
    CHECK(f >= 0 && v3_dist(fx.part->hull->normal[f], expect_normal) < 1e-9);
    CHECK_NEAR(s.x.z, facet_height(&fx, f), 0.01 * PD_BULLET_MARGIN_REL * fx.body->size,
               "resting on that face, 1% of the margin");
    teardown(&fx);
}

/* Two drops with contacts, one bounce: the final states, byte for byte. */
static void drop(fixture *fx, pd_state *out)
{
    pd_state s0 = {v3(0.0, 0.0, 0.04), quat_normalize(quat(0.8, 0.3, -0.4, 0.2)),
                   v3(0.05, 0.0, 0.0), v3(2.0, -7.0, 4.0)};
    memset(out, 0, sizeof *out);
    *out = s0;
    CHECK_STATUS(pd_engine_bullet.reset(fx->w, &s0), PD_OK);
    CHECK(run(fx, out, 480));
}

static void test_determinism(void)
{
    fixture a, b;
    if (!setup(&a, 0.01, 0.02, 0.03))
        return;
    if (!setup(&b, 0.01, 0.02, 0.03)) {
        teardown(&a);
        return;
    }
    pd_state s1, s2, s3;
    drop(&a, &s1);
    drop(&b, &s2); /* a fresh world */
    drop(&a, &s3); /* the same world again: reset must leave no trace */
    CHECK(memcmp(&s1, &s2, sizeof s1) == 0);
    CHECK(memcmp(&s1, &s3, sizeof s1) == 0);
    CHECK(s1.x.z < 0.03); /* it did reach the floor */
    teardown(&b);
    teardown(&a);
}

/* A fast spin: a 1 x 1 x 0.01 mm flake turning at ~3700 rad/s about no
 * principal axis, 3.9 rad per step (what a bounce at e = 1 gives it). The
 * torque-free motion keeps its energy and angular momentum; an explicit
 * gyroscopic step gains energy without bound there (1e29 times within a
 * second of a drop). Backward Euler only loses energy: after 960 steps the
 * energy may have fallen, never risen beyond float round-off (1e-5). */
static void test_fast_spin(void)
{
    fixture fx;
    if (!setup(&fx, 0.001, 0.001, 0.00001))
        return;
    fx.scene.gravity = 0.0;
    pd_engine_bullet.world_free(fx.w);
    fx.w = pd_engine_bullet.world_alloc(fx.body, fx.part->hull, &fx.scene, DT);
    CHECK(fx.w != NULL);
    if (!fx.w) {
        teardown(&fx);
        return;
    }
    pd_state s0 = {v3(0, 0, 1.0), quat_normalize(quat(0.9, 0.2, -0.3, 0.1)), v3(0, 0, 0),
                   v3(3000.0, 500.0, 2000.0)};
    pd_state s = s0;
    CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s0), PD_OK);
    CHECK(run(&fx, &s, 960));
    const double *I = fx.body->moment;
    double e0 = I[0] * s0.w.x * s0.w.x + I[1] * s0.w.y * s0.w.y + I[2] * s0.w.z * s0.w.z;
    double e1 = I[0] * s.w.x * s.w.x + I[1] * s.w.y * s.w.y + I[2] * s.w.z * s.w.z;
    CHECK(isfinite(e1) && e1 <= e0 * (1.0 + 1e-5));
    teardown(&fx);
}

/* Drilling friction, as test_engine_ode.c's top: a regular octahedron
 * balanced on a corner and spun about the vertical, under the scene's
 * contact (T = 5e-4 s, 20 steps per contact). The corner does not slip, so
 * only the couple over its patch, (2/3) mu a m g with a = sqrt(R L g) /
 * omega (the law's sink under the weight, d = g / omega^2), slows it:
 * w(t) = w0 - C t / I until t* = I w0 / C, then stopped. Without the couple
 * (before 2026-12-07) the spin stayed w0. */
static void test_drilling_top(void)
{
    pd_vec3 p[6];
    int n = pts_octahedron(p);
    for (int i = 0; i < n; i++)
        p[i] = v3_scale(p[i], 0.005);
    fixture fx;
    memset(&fx, 0, sizeof fx);
    pd_scene_default(&fx.scene);
    fx.scene.contact_time = 5e-4;
    double dt = fx.scene.contact_time / 20.0;
    pd_mesh *mesh = convex_mesh(p, n);
    int ok = mesh && pd_part_build(mesh, NULL, &fx.part, NULL) == PD_OK &&
             pd_body_build(fx.part, &fx.body, NULL) == PD_OK &&
             (fx.w = pd_engine_bullet.world_alloc(fx.body, fx.part->hull, &fx.scene, dt)) != NULL;
    pd_mesh_free(mesh);
    CHECK(ok);
    if (!ok) {
        teardown(&fx);
        return;
    }
    const pd_body *b = fx.body;
    double g = fx.scene.gravity, L = b->size, omega, zeta;
    pd_engine_contact_law(fx.scene.contact_time, fx.scene.restitution, &omega, &zeta);
    pd_vec3 c = quat_rotate_inv(b->frame, v3_sub(v3(0, 0, -0.005), b->com));
    /* The corner (0, 0, -r) of the part frame, in the principal frame,
     * turned straight down. */
    pd_state s = {v3(0, 0, v3_norm(c)), quat_between(v3_unit(c), v3(0, 0, -1)), v3(0, 0, 0),
                  v3(0, 0, 0)};
    double w0 = 1.0;
    s.w = quat_rotate_inv(s.q, v3(0, 0, w0));
    double a = sqrt(PD_CORNER_RADIUS_REL * L * g) / omega;
    double couple = 2.0 / 3.0 * fx.scene.mu * a * b->mass * g;
    double I = b->moment[2], t_stop = I * w0 / couple;
    CHECK_STATUS(pd_engine_bullet.reset(fx.w, &s), PD_OK);
    int half = (int)(0.5 * t_stop / dt);
    CHECK(run(&fx, &s, half));
    double spin = quat_rotate(s.q, s.w).z;
    pd_note("engine_bullet: drilling top spins at %.6g rad/s at %.4g s, predicted %.6g (stops at "
            "%.4g s)\n", spin, half * dt, w0 - couple * half * dt / I, t_stop);
    /* 2% of w0, as ODE's: the load settling onto the spring at the start. */
    CHECK_NEAR(spin, w0 - couple * half * dt / I, 0.02 * w0, "constant couple (2/3) mu a m g");
    CHECK(run(&fx, &s, (int)(1.5 * t_stop / dt) - half));
    spin = quat_rotate(s.q, s.w).z;
    CHECK_NEAR(spin, 0.0, 1e-3 * w0, "stopped at t* and held by static drilling friction");
    CHECK(s.x.z > 0.9 * v3_norm(c)); /* still on its corner */
    teardown(&fx);
}

void suite_engine_bullet(void)
{
    test_drilling_top();
    CHECK(strcmp(pd_engine_bullet.name, "bullet") == 0);
    test_free_flight();
    test_reset_read_back();
    test_rest_on_each_face(0.01, 0.02, 0.03);
    test_rest_on_each_face(1.0, 0.01, 0.01);
    test_flat_from_1mm();
    test_topple(2.0 * M_PI / 180.0, v3(0, 0, -1));
    test_topple(-2.0 * M_PI / 180.0, v3(-1, 0, 0));
    test_determinism();
    test_fast_spin();
}
