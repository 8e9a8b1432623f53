/* test_engine_contact.c: the scene's contact (contact_time T > 0,
 * restitution e) in the stepping engines: the spring-dashpot of
 * pd_engine_contact_law against its closed form, then ODE and Bullet
 * striking the floor with one corner and rebounding with e after a contact
 * of T, to first order in the step. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "dynamics/body.h"
#include "impact/impact.h"
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

/* A corner strike with Coulomb friction in the plane x-z, against the
 * rigid impulse in closed form. The 1 cm cube is turned 45 degrees about z
 * and tilted 45 degrees about y, so that one corner, at r = (0.29, 0,
 * -1.71) half-sides from the centre of mass, is lowest by a whole
 * half-side; the cube's inertia is isotropic, so the collision matrix K
 * couples x and z only, and a strike moving in that plane stays in it.
 * With a = K_xx, b = K_xz, c = K_zz and the corner's velocity u0:
 *   sliding along s = sign(u0x) throughout: p_x = -s mu p_z, so the normal
 *     velocity grows at c - s mu b per unit p_z, maximum compression at
 *     p_zc = -u0z / (c - s mu b), and the slip at b - s mu a (the slip
 *     must keep its sign up to the end);
 *   sticking throughout (u0x = 0, |b| <= mu a): p_x = -(b / a) p_z and the
 *     normal velocity grows at c - b^2 / a.
 * Restitution ends at p_z = (1 + e') p_zc. In both cases the ratio p_x / p_z
 * is fixed, so the normal inverse mass along the impulse is constant and
 * the compliant contact's rigid limit is this impulse (docs/contact.md,
 * "The rigid limit"), with e' the rebound of the engines' spring-dashpot
 * on that normal mass: not the scene's e, which the law gives for the
 * frictionless normal mass 1 / c (e' = 0.314 sticking, 0.332 and 0.275
 * sliding, against e = 0.3: docs/engines-crosscheck.md). Stick-slip
 * transitions are left out: there the rigid limit and Poisson's law part. */
typedef struct {
    pd_vec3 v, w; /* world, m/s and rad/s */
} twist;

/* The cube turned so that its corner c is lowest with r_y = 0; *r is that
 * corner (world, from the centre of mass). */
static pd_quat tilted_cube(const pd_body *b, int *c, pd_vec3 *r)
{
    pd_quat q = quat_mul(quat_axis_angle(v3(0, 1, 0), M_PI / 4),
                         quat_mul(quat_axis_angle(v3(0, 0, 1), -M_PI / 4), b->frame));
    *c = pd_body_support_scan(b, quat_rotate_inv(q, v3(0, 0, 1)));
    *r = quat_rotate(q, b->verts[*c]);
    return q;
}

/* The world inverse inertia of b at orientation q, applied to x. */
static pd_vec3 inv_inertia(const pd_body *b, pd_quat q, pd_vec3 x)
{
    return quat_rotate(q, pd_body_inv_inertia(b, quat_rotate_inv(q, x)));
}

/* K's column for a unit impulse along axis k: the corner's velocity change. */
static pd_vec3 k_column(const pd_body *b, pd_quat q, pd_vec3 r, pd_vec3 axis)
{
    return v3_add(v3_scale(axis, 1.0 / b->mass),
                  v3_cross(inv_inertia(b, q, v3_cross(r, axis)), r));
}

/* The rigid limit of the engines' law in closed form (above), or 0 if the
 * strike is in neither regime or leaves the plane. zeta: the law's damping
 * ratio for the scene's e. */
static int planar_impact(const pd_body *b, pd_quat q, pd_vec3 r, twist in, double mu,
                         double zeta, twist *out)
{
    pd_vec3 kx = k_column(b, q, r, v3(1, 0, 0)), kz = k_column(b, q, r, v3(0, 0, 1));
    double a = kx.x, bb = kz.x, c = kz.z;
    pd_vec3 u0 = v3_add(in.v, v3_cross(in.w, r));
    /* Decoupled to round-off (isotropic inertia, r_y = 0). */
    if (fabs(kx.y) > 1e-9 * a || fabs(kz.y) > 1e-9 * a || fabs(u0.y) > 1e-12 || !(u0.z < 0.0))
        return 0;
    double sgn = u0.x > 0.0 ? 1.0 : -1.0;
    double ratio = u0.x == 0.0 ? -bb / a : -sgn * mu;
    double rate = c + ratio * bb; /* c - b^2 / a sticking, c - s mu b sliding */
    if (!(rate > 0.0) || (u0.x == 0.0 && fabs(bb) > mu * a))
        return 0;
    /* The law's stiffness and damping are fitted to the frictionless normal
     * mass 1 / c; along this impulse the normal mass is 1 / rate, and the
     * same spring-dashpot on that mass has the damping ratio
     * zeta sqrt(rate / c), hence its own rebound. */
    double zeta_f = zeta * sqrt(rate / c);
    double ef = exp(-zeta_f * push_only_duration(zeta_f));
    double pz = (1.0 + ef) * -u0.z / rate;
    if (u0.x != 0.0 && !(sgn * (u0.x + (bb + ratio * a) * pz) > 0.0))
        return 0; /* the slip would stop */
    pd_vec3 p = v3(ratio * pz, 0, pz);
    out->v = v3_add(in.v, v3_scale(p, 1.0 / b->mass));
    out->w = v3_add(in.w, inv_inertia(b, q, v3_cross(r, p)));
    return 1;
}

/* The engine's outcome of that strike without gravity, stepping dt until
 * ten steps after the last that changed the velocity; 0 if it fails or
 * another corner touches. */
static int engine_strike(const pd_engine *eng, const pd_body *b, const pd_hull *h,
                         const pd_scene *sc, double dt, pd_quat q, int c, twist in, twist *out)
{
    pd_vec3 r = quat_rotate(q, b->verts[c]);
    double uz = in.v.z + v3_cross(in.w, r).z;
    pd_state s = {v3(-r.x, -r.y, -r.z - 0.5 * uz * dt), q, in.v, quat_rotate_inv(q, in.w)};
    pd_engine_world *w = eng->world_alloc(b, h, sc, dt);
    if (!w || eng->reset(w, &s) != PD_OK) {
        if (w)
            eng->world_free(w);
        return 0;
    }
    long first = -1, after = 0;
    int ok = 1;
    /* The contact lasts a few hundred steps; 1e5 bound the loop. */
    for (long k = 0; ok && k < 100000 && after < 10; k++) {
        pd_vec3 v = s.v;
        ok = eng->step(w, &s) == PD_OK;
        for (int i = 0; ok && i < b->nverts; i++)
            ok = i == c || v3_add(s.x, quat_rotate(s.q, b->verts[i])).z > 0.0;
        if (v3_norm(v3_sub(s.v, v)) > 1e-9 * v3_norm(v))
            first = k, after = 0;
        else if (first >= 0)
            after++;
    }
    eng->world_free(w);
    out->v = s.v;
    out->w = quat_rotate(s.q, s.w);
    return ok && after >= 10;
}

/* The strike's error: the outgoing velocity and angular velocity (times the
 * farthest corner's distance) off the closed form, over the corner's
 * approach speed. */
static double strike_error(const pd_body *b, twist got, twist want, double speed)
{
    double dv = v3_norm(v3_sub(got.v, want.v));
    double dw = v3_norm(v3_sub(got.w, want.w)) * b->rmax;
    return fmax(dv, dw) / speed;
}

/* Both engines, mu 0.3, e 0.3, contact_time 1e-4 s, at T / 200 and T / 400
 * steps (Bullet does not step below FLT_EPSILON s, 1.2e-7): sticking
 * throughout (straight down), sliding throughout along +x (63 degrees from
 * the normal), and along -x with a spin about y. Two errors, both stated:
 * the engines' first-order one in the rebound, |e' - e| <= 5 h / T
 * (test_corner_impacts), which moves the outgoing velocities by at most
 * that times the approach speed; and the cube's turn during the contact,
 * at most w T with w the larger spin before or after, which turns r and
 * with it K and the impulse by that share. So within 5 h / T + w T of the
 * closed form at both steps. Until 2026-11-28 ODE's friction rows took the
 * contact spring's cfm, a damper that could not stop a slip within the
 * contact, and the sticking strike was 0.2 of the speed off. */
static void test_corner_friction(void)
{
    pd_part *part;
    pd_body *b;
    if (!cube(&part, &b))
        return;
    int c;
    pd_vec3 r;
    pd_quat q = tilted_cube(b, &c, &r);
    CHECK_NEAR(r.y, 0.0, 1e-12 * b->size, "corner in the plane x-z");
    const twist strikes[3] = {{v3(0, 0, -1), v3(0, 0, 0)},
                              {v3(2, 0, -1), v3(0, 0, 0)},
                              {v3(-3, 0, -1), v3(0, -50, 0)}};
    const pd_engine *engines[2] = {&pd_engine_ode, &pd_engine_bullet};
    pd_scene sc;
    pd_scene_default(&sc);
    sc.gravity = 0.0;
    sc.mu = 0.3;
    sc.restitution = 0.3;
    sc.contact_time = 1e-4;
    double omega, zeta;
    pd_engine_contact_law(sc.contact_time, sc.restitution, &omega, &zeta);
    for (int i = 0; i < 3; i++) {
        twist want;
        int regime = planar_impact(b, q, r, strikes[i], sc.mu, zeta, &want);
        CHECK(regime);
        if (!regime)
            continue;
        double speed = v3_norm(v3_add(strikes[i].v, v3_cross(strikes[i].w, r)));
        double turn = fmax(v3_norm(strikes[i].w), v3_norm(want.w)) * sc.contact_time;
        for (int k = 0; k < 2; k++)
            for (int n = 200; n <= 400; n *= 2) {
                twist got;
                int ok = engine_strike(engines[k], b, part->hull, &sc, sc.contact_time / n, q, c,
                                       strikes[i], &got);
                CHECK(ok);
                if (ok)
                    CHECK_NEAR(strike_error(b, got, want, speed), 0.0, 5.0 / n + turn,
                               "first order 5 h / T, plus the turn w T during the contact");
            }
    }
    pd_body_free(b);
    pd_part_free(part);
}

/* A corner strike sliding throughout in 3-D: the cube turned 45 degrees
 * about z, 30 about y and 30 about z again, so that the collision matrix
 * couples the slip's two directions with each other and with the normal,
 * and the slip turns during the impact; it strikes at (2, 0.5, -1) m/s,
 * mu 0.3, e 0.3, contact_time 1e-4 s, no gravity. Coulomb's law gives a
 * sliding contact a friction of exactly mu N against its slip and none
 * across it, so the total impulse has |p_t| <= mu p_z, equal only if the
 * slip kept its direction; the rigid law (pd_impact_solve, which the
 * strike must not stick in) gives |p_t| = 0.9989 mu p_z. Each engine clamps
 * its friction to mu times the normal impulse of the same solve, step by
 * step, so the bound holds to the solvers' round-off (1e-6 taken); over
 * p_z the slip follows the same path as in the rigid law (du = K dp, dp =
 * (-mu s, 1) dp_z), to the engines' first order in the step, so the ratio
 * is within 5 h / T below the rigid law's. Before 2026-11-28 both engines
 * gave a sliding contact a second friction row across its slip, which held
 * the slip's direction with up to mu N more: |p_t| = 1.05 mu p_z here. */
static void test_sliding_turns(void)
{
    pd_part *part;
    pd_body *b;
    if (!cube(&part, &b))
        return;
    pd_quat q = quat_mul(quat_axis_angle(v3(0, 0, 1), M_PI / 6),
                         quat_mul(quat_axis_angle(v3(0, 1, 0), M_PI / 6),
                                  quat_mul(quat_axis_angle(v3(0, 0, 1), -M_PI / 4), b->frame)));
    int c = pd_body_support_scan(b, quat_rotate_inv(q, v3(0, 0, 1)));
    pd_vec3 r = quat_rotate(q, b->verts[c]);
    twist in = {v3(2, 0.5, -1), v3(0, 0, 0)};
    pd_scene sc;
    pd_scene_default(&sc);
    sc.gravity = 0.0;
    sc.contact_time = 1e-4;
    double K[3][3], J[3][3];
    for (int i = 0; i < 3; i++) {
        pd_vec3 col = inv_inertia(b, q, v3(i == 0, i == 1, i == 2));
        J[0][i] = col.x;
        J[1][i] = col.y;
        J[2][i] = col.z;
    }
    pd_impact_K(1.0 / b->mass, CONST_M3(J), r, K);
    pd_impact_work *iw = pd_impact_work_alloc();
    pd_impact_result rigid;
    int ok = iw && pd_impact_solve(iw, CONST_M3(K), in.v, sc.mu, sc.restitution,
                                   PD_IMPACT_POISSON, &rigid) == PD_OK;
    pd_impact_work_free(iw);
    CHECK(ok && !rigid.stuck);
    double want = ok ? hypot(rigid.p.x, rigid.p.y) / (sc.mu * rigid.p.z) : 0.0;
    const pd_engine *engines[2] = {&pd_engine_ode, &pd_engine_bullet};
    for (int k = 0; ok && k < 2; k++)
        for (int n = 200; n <= 400; n *= 2) {
            twist got;
            int struck = engine_strike(engines[k], b, part->hull, &sc, sc.contact_time / n, q, c,
                                       in, &got);
            CHECK(struck);
            if (!struck)
                continue;
            pd_vec3 p = v3_scale(v3_sub(got.v, in.v), b->mass);
            double ratio = hypot(p.x, p.y) / (sc.mu * p.z);
            CHECK(ratio <= 1.0 + 1e-6);
            CHECK_NEAR(ratio, want, 5.0 / n, "the rigid law's slip path, first order 5 h / T");
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
    test_corner_friction();
    test_sliding_turns();
    test_unresolved();
}
