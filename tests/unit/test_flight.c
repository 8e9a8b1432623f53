/* test_flight.c: the rigid-body model, torque-free flight and the impact
 * search. Oracles: closed forms (box moments, free fall, symmetric-top
 * precession), conservation laws, an independent fine-step RK4 integration of
 * q and omega, and brute-force scans (all vertices, fine time grids). */
#include <stdlib.h>
#include <string.h>
#include "dynamics/body.h"
#include "check.h"
#include "dynamics/flight.h"
#include "base/gsl_adapter.h"
#include "posedrop/posedrop.h"
#include "posedrop/tolerances.h"
#include "dynamics/dynamics_tol.h"
#include "shapes.h"
#include "base/sincos.h"
#include "suites.h"
#include "base/vec3.h"

static const double G = 9.81;

static pd_part *part_of_mesh(pd_mesh *m)
{
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    pd_mesh_free(m);
    return p;
}

static pd_body *body_of(const pd_part *p)
{
    pd_body *b = NULL;
    CHECK_STATUS(pd_body_build(p, &b, NULL), PD_OK);
    return b;
}

/* A random unit quaternion (not uniform over rotations). */
static pd_quat random_quat(test_rng *r)
{
    return quat_normalize(quat(rng_range(r, -1, 1), rng_range(r, -1, 1), rng_range(r, -1, 1),
                               rng_range(r, -1, 1)));
}

/* Raises or lowers s so that its lowest vertex is gap above the floor. */
static void lift(const pd_body *b, pd_state *s, double gap)
{
    int low = pd_body_support_scan(b, quat_rotate_inv(s->q, v3(0, 0, 1)));
    s->x.z = -pd_body_vertex_world(b, s, low).z + gap;
}

/* p's body; NULL, a failed check and p freed when p is NULL or has none. */
static pd_body *body_or_free(pd_part *p)
{
    pd_body *b = p ? body_of(p) : NULL;
    if (!b) {
        CHECK(0);
        pd_part_free(p);
    }
    return b;
}

/* max(worst, e) keeping a NaN on either side, so that a NaN reaches the
 * check (fmax and e > worst ? e : worst drop it). */
static double worse(double worst, double e)
{
    return isnan(worst) || e <= worst ? worst : e;
}

static pd_vec3 world_L(const pd_body *b, const pd_state *s)
{
    return quat_rotate(s->q, v3(b->moment[0] * s->w.x, b->moment[1] * s->w.y,
                                b->moment[2] * s->w.z));
}

static double energy(const pd_body *b, const pd_state *s)
{
    return 0.5 * (b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                  b->moment[2] * s->w.z * s->w.z);
}

/* Reference: classical RK4 on (q, omega) with q' = q (0, w) / 2 and Euler's
 * equations, fine fixed steps; shares nothing with the closed form. */
static void rk4_deriv(const pd_body *b, pd_quat q, pd_vec3 w, pd_quat *dq, pd_vec3 *dw)
{
    pd_quat p = quat_mul(q, quat(0.0, w.x, w.y, w.z));
    *dq = quat(0.5 * p.w, 0.5 * p.x, 0.5 * p.y, 0.5 * p.z);
    const double *I = b->moment;
    *dw = v3((I[1] - I[2]) * w.y * w.z / I[0], (I[2] - I[0]) * w.z * w.x / I[1],
             (I[0] - I[1]) * w.x * w.y / I[2]);
}

static pd_quat qax(pd_quat q, pd_quat d, double h)
{
    return quat(q.w + h * d.w, q.x + h * d.x, q.y + h * d.y, q.z + h * d.z);
}

static void rk4_rotate(const pd_body *b, pd_quat *q, pd_vec3 *w, double T, int nsteps)
{
    double h = T / nsteps;
    for (int i = 0; i < nsteps; i++) {
        pd_quat k1q, k2q, k3q, k4q;
        pd_vec3 k1w, k2w, k3w, k4w;
        rk4_deriv(b, *q, *w, &k1q, &k1w);
        rk4_deriv(b, qax(*q, k1q, h / 2), v3_add(*w, v3_scale(k1w, h / 2)), &k2q, &k2w);
        rk4_deriv(b, qax(*q, k2q, h / 2), v3_add(*w, v3_scale(k2w, h / 2)), &k3q, &k3w);
        rk4_deriv(b, qax(*q, k3q, h), v3_add(*w, v3_scale(k3w, h)), &k4q, &k4w);
        *q = quat_normalize(quat(
            q->w + h / 6 * (k1q.w + 2 * k2q.w + 2 * k3q.w + k4q.w),
            q->x + h / 6 * (k1q.x + 2 * k2q.x + 2 * k3q.x + k4q.x),
            q->y + h / 6 * (k1q.y + 2 * k2q.y + 2 * k3q.y + k4q.y),
            q->z + h / 6 * (k1q.z + 2 * k2q.z + 2 * k3q.z + k4q.z)));
        *w = v3_add(*w, v3_scale(v3_add(v3_add(k1w, v3_scale(k2w, 2)),
                                        v3_add(v3_scale(k3w, 2), k4w)), h / 6));
    }
}

/* Rotation distance between two orientations, radians. */
static double quat_angle(pd_quat a, pd_quat b)
{
    pd_quat d = quat_mul(quat_conj(a), b);
    return 2.0 * atan2(sqrt(d.x * d.x + d.y * d.y + d.z * d.z), fabs(d.w));
}

static void test_eigen(void)
{
    /* Box a x b x c: I = V/12 diag(b^2+c^2, a^2+c^2, a^2+b^2). */
    pd_part *p = part_of_mesh(mesh_box(1.0, 2.0, 3.0));
    pd_body *b = p ? body_of(p) : NULL;
    if (b) {
        CHECK_REL(b->mass, 6.0, 1e-14, "closed form, round-off");
        CHECK_REL(b->moment[0], 6.0 / 12.0 * (1.0 + 4.0), 1e-13, "closed form, round-off");
        CHECK_REL(b->moment[1], 6.0 / 12.0 * (1.0 + 9.0), 1e-13, "closed form, round-off");
        CHECK_REL(b->moment[2], 6.0 / 12.0 * (4.0 + 9.0), 1e-13, "closed form, round-off");
        double rmax = 0.5 * sqrt(14.0);
        CHECK_REL(b->rmax, rmax, 1e-14, "half diagonal, round-off");
    }
    pd_body_free(b);
    pd_part_free(p);

    /* Random rotated tensors: R diag R^T reproduces A, eigenvalues match. */
    test_rng r = {7};
    double worst_rec = 0.0, worst_eig = 0.0, worst_orth = 0.0;
    for (int trial = 0; trial < 200; trial++) {
        double R[3][3], d[3] = {rng_range(&r, 0.1, 3), rng_range(&r, 0.1, 3), rng_range(&r, 0.1, 3)};
        if (trial % 3 == 0)
            d[1] = d[0]; /* repeated eigenvalue */
        rng_rotation(&r, R);
        double A[3][3], eval[3], V[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                A[i][j] = 0.0;
                for (int k = 0; k < 3; k++)
                    A[i][j] += R[i][k] * d[k] * R[j][k];
            }
        pd_sym_eigen3(CONST_M3(A), eval, V);
        double ds[3] = {d[0], d[1], d[2]};
        for (int i = 0; i < 3; i++)
            for (int j = i + 1; j < 3; j++)
                if (ds[j] < ds[i]) {
                    double t = ds[i];
                    ds[i] = ds[j];
                    ds[j] = t;
                }
        for (int i = 0; i < 3; i++) {
            double e = fabs(eval[i] - ds[i]) / ds[2];
            worst_eig = e > worst_eig ? e : worst_eig;
            for (int j = 0; j < 3; j++) {
                double a = 0.0, o = 0.0;
                for (int k = 0; k < 3; k++) {
                    a += V[i][k] * eval[k] * V[j][k];
                    o += V[k][i] * V[k][j];
                }
                a = fabs(a - A[i][j]) / ds[2];
                o = fabs(o - (i == j));
                worst_rec = a > worst_rec ? a : worst_rec;
                worst_orth = o > worst_orth ? o : worst_orth;
            }
        }
    }
    CHECK_NEAR(worst_eig, 0.0, 1e-14, "eigenvalues vs construction, round-off");
    CHECK_NEAR(worst_rec, 0.0, 1e-12, "V diag V^T = A relative to |A|, round-off");
    CHECK_NEAR(worst_orth, 0.0, 1e-14, "V^T V = 1, round-off");
}

static pd_state state_at(pd_vec3 x, pd_quat q, pd_vec3 v, pd_vec3 w)
{
    pd_state s = {x, q, v, w};
    return s;
}

static void check_conservation(const pd_body *b, pd_state s0, double T, const char *what)
{
    pd_flight f;
    CHECK_STATUS(pd_flight_plan(b, &s0, G, &f), PD_OK);
    pd_vec3 L0 = world_L(b, &s0);
    double E0 = energy(b, &s0), worstE = 0.0, worstL = 0.0;
    int failed = 0;
    for (int i = 1; i <= 200; i++) {
        pd_state s;
        failed += pd_flight_eval(&f, T * i / 200, &s) != PD_OK;
        double eE = fabs(energy(b, &s) - E0) / E0;
        double eL = v3_dist(world_L(b, &s), L0) / v3_norm(L0);
        worstE = eE > worstE ? eE : worstE;
        worstL = eL > worstL ? eL : worstL;
    }
    CHECK_INT(failed, 0);
    if (worstE > 1e-10 || worstL > 1e-10)
        printf("     %s\n", what);
    CHECK_NEAR(worstE, 0.0, 1e-10, "energy conservation, requirement");
    CHECK_NEAR(worstL, 0.0, 1e-10, "world angular momentum conservation, requirement");
}

/* Closed form against fine RK4 after T: RK4 at h = 1e-5 s and |w| h <= 5e-4
 * has global error ~ (w h)^4 w T ~ 1e-12; 1e-8 rad leaves room. */
static void check_vs_rk4(const pd_body *b, pd_state s0, double T)
{
    pd_flight f;
    pd_state s;
    CHECK_STATUS(pd_flight_plan(b, &s0, G, &f), PD_OK);
    CHECK_STATUS(pd_flight_eval(&f, T, &s), PD_OK);
    pd_quat q = s0.q;
    pd_vec3 w = s0.w;
    rk4_rotate(b, &q, &w, T, (int)(T / 1e-5));
    CHECK_NEAR(quat_angle(q, s.q), 0.0, 1e-8, "RK4 reference, h = 1e-5 s");
    CHECK_NEAR(v3_dist(w, s.w) / v3_norm(w), 0.0, 1e-8, "RK4 reference, h = 1e-5 s");
}

static void test_flight(void)
{
    pd_part *p = part_of_mesh(mesh_box(0.01, 0.02, 0.03));
    pd_body *b = p ? body_of(p) : NULL;
    if (!b) {
        pd_part_free(p);
        return;
    }
    /* Ballistic com: exact closed form (the same expression up to round-off). */
    pd_state s0 = state_at(v3(0.1, -0.2, 0.3), quat_identity(), v3(0.5, 0.25, 1.0), v3(0, 0, 0));
    pd_state s;
    CHECK_STATUS(pd_flight_advance(b, &(pd_state){s0.x, s0.q, s0.v, s0.w}, G, 0.2), PD_OK);
    pd_flight f;
    CHECK_STATUS(pd_flight_plan(b, &s0, G, &f), PD_OK);
    CHECK_STATUS(pd_flight_eval(&f, 0.2, &s), PD_OK);
    CHECK_NEAR(s.x.x, 0.1 + 0.5 * 0.2, 1e-16, "x + v t, round-off");
    CHECK_NEAR(s.x.z, 0.3 + 0.2 - 0.5 * G * 0.04, 1e-16, "x + v t - g t^2/2, round-off");
    CHECK_NEAR(s.v.z, 1.0 - G * 0.2, 1e-15, "v - g t, round-off");

    /* Asymmetric 1:2:3 box, random omega up to 50 rad/s, 2 s. */
    test_rng r = {11};
    for (int i = 0; i < 6; i++) {
        pd_vec3 w = v3_scale(rng_unit_vector(&r), rng_range(&r, 5.0, 50.0));
        pd_quat q = random_quat(&r);
        check_conservation(b, state_at(v3(0, 0, 1), q, v3(0, 0, 0), w), 2.0, "random omega");
        if (i < 2)
            check_vs_rk4(b, state_at(v3(0, 0, 1), q, v3(0, 0, 0), v3_scale(w, 0.2)), 0.5);
    }
    /* Near the unstable middle axis: the tennis-racket flip. omega mostly
     * along axis 2 with a 1e-3 perturbation: omega_2 reverses within 2 s. */
    pd_state sr = state_at(v3(0, 0, 1), quat_identity(), v3(0, 0, 0), v3(1e-2, 20.0, 1e-2));
    check_conservation(b, sr, 2.0, "middle axis");
    check_vs_rk4(b, sr, 1.0);
    CHECK_STATUS(pd_flight_plan(b, &sr, G, &f), PD_OK);
    double wmin = 1e300;
    for (int i = 1; i <= 400; i++) {
        CHECK_STATUS(pd_flight_eval(&f, 2.0 * i / 400, &s), PD_OK);
        wmin = s.w.y < wmin ? s.w.y : wmin;
    }
    CHECK(wmin < -19.0); /* flipped: omega_2 near -20 (energy closed form) */
    /* Within round-off of the middle axis, as contact phases rotating the box
     * about an edge leave it (off-axis ~1e-14 to ~1e-8): the separatrix's end,
     * where the elliptic phase overflows. Planned as a steady spin, which
     * conserves energy and momentum like every other flight. */
    const double eps[] = {1e-14, 6.5e-9, 1e-7};
    for (int i = 0; i < 3; i++) {
        pd_state sn = state_at(v3(0, 0, 1), quat_identity(), v3(0, 0, 0),
                               v3(eps[i] * 10.0, 10.0, -eps[i] * 8.0));
        CHECK_STATUS(pd_flight_plan(b, &sn, G, &f), PD_OK);
        check_conservation(b, sn, 0.5, "near the middle axis");
    }
    /* Exactly on the principal axes: steady spins, also the unstable one. */
    for (int a = 0; a < 3; a++) {
        pd_vec3 w = v3(a == 0 ? 30.0 : 0.0, a == 1 ? 30.0 : 0.0, a == 2 ? 30.0 : 0.0);
        CHECK_STATUS(pd_flight_advance(b, &(pd_state){v3(0, 0, 0), quat_identity(), v3(0, 0, 0), w},
                                       G, 2.0), PD_OK);
    }
    pd_body_free(b);
    pd_part_free(p);

    /* Symmetric top (1 x 1 x 3 box: I1 = I2 < I3... no: I1 = I2 > I3). The
     * symmetry axis precesses about L at |L| / I1 (closed form, Landau sec. 33). */
    p = part_of_mesh(mesh_box(0.01, 0.01, 0.03));
    b = p ? body_of(p) : NULL;
    if (b) {
        int d = b->moment[0] == b->moment[1] ? 2 : 0;
        CHECK(b->moment[0] == b->moment[1] || b->moment[1] == b->moment[2]);
        pd_vec3 ax = d == 2 ? v3(0, 0, 1) : v3(1, 0, 0);
        pd_state st = state_at(v3(0, 0, 0), quat_identity(), v3(0, 0, 0), v3(3.0, 1.0, 7.0));
        check_conservation(b, st, 2.0, "symmetric top");
        check_vs_rk4(b, st, 0.5);
        CHECK_STATUS(pd_flight_plan(b, &st, G, &f), PD_OK);
        pd_vec3 L = world_L(b, &st), lh = v3_unit(L);
        double Ieq = b->moment[d == 2 ? 0 : 2];
        double rate = v3_norm(L) / Ieq, T = 0.3;
        CHECK_STATUS(pd_flight_eval(&f, T, &s), PD_OK);
        /* Angle swept by the symmetry axis about L, projected on L's plane. */
        pd_vec3 a0 = v3_sub(ax, v3_scale(lh, v3_dot(ax, lh)));
        pd_vec3 a1w = quat_rotate(s.q, ax);
        pd_vec3 a1 = v3_sub(a1w, v3_scale(lh, v3_dot(a1w, lh)));
        double ang = atan2(v3_dot(v3_cross(a0, a1), lh), v3_dot(a0, a1));
        double want = remainder(rate * T, 2.0 * 3.14159265358979323846);
        CHECK_NEAR(ang, want, 1e-12, "precession |L|/I1, closed form, round-off");
    }
    pd_body_free(b);
    pd_part_free(p);

    /* Spherical top (cube): omega constant, q = q0 exp(w t). */
    p = part_of_mesh(mesh_box(0.02, 0.02, 0.02));
    b = p ? body_of(p) : NULL;
    if (b) {
        CHECK(b->moment[0] == b->moment[2]);
        pd_vec3 w = v3(3.0, -4.0, 12.0);
        pd_state st = state_at(v3(0, 0, 0), quat_axis_angle(v3(0, 1, 0), 0.3), v3(0, 0, 0), w);
        CHECK_STATUS(pd_flight_plan(b, &st, G, &f), PD_OK);
        CHECK_STATUS(pd_flight_eval(&f, 1.7, &s), PD_OK);
        CHECK_NEAR(v3_dist(s.w, w), 0.0, 1e-13, "constant omega, round-off");
        CHECK_NEAR(quat_angle(s.q, quat_mul(st.q, quat_exp(v3_scale(w, 1.7)))), 0.0, 1e-13,
                   "q0 exp(w t), round-off");
    }
    pd_body_free(b);
    pd_part_free(p);
}

/* Reference for the closed form: GSL's Prince-Dormand 8(9) on q' = q (0, w) / 2
 * and Euler's equations, held to 1e-14 relative per step; shares no formula
 * with flight.c. y = (q, w), renormalised only when compared. */
static int euler_rhs(double t, const double y[], double dy[], void *user)
{
    (void)t;
    const double *I = user;
    double w0 = y[4], w1 = y[5], w2 = y[6];
    dy[0] = 0.5 * (-y[1] * w0 - y[2] * w1 - y[3] * w2);
    dy[1] = 0.5 * (y[0] * w0 + y[2] * w2 - y[3] * w1);
    dy[2] = 0.5 * (y[0] * w1 + y[3] * w0 - y[1] * w2);
    dy[3] = 0.5 * (y[0] * w2 + y[1] * w1 - y[2] * w0);
    dy[4] = (I[1] - I[2]) * w1 * w2 / I[0];
    dy[5] = (I[2] - I[0]) * w2 * w0 / I[1];
    dy[6] = (I[0] - I[1]) * w0 * w1 / I[2];
    return 0;
}

/* The flight of a body of moments I (ascending) from orientation q and body
 * rate w against the ODE over T, sampled 20 times: the worst rotation angle
 * (rad) and relative rate error go into worst[0], worst[1], the larger of
 * them times 1 - m (the separatrix's amplification, see below) into
 * worst[2]; flags[0] counts polhodes about the largest moment, flags[1]
 * flights by theta series. Only the moments enter the flight, so a bare body
 * serves. */
static void vs_ode(pd_ode *ode, const double I[3], pd_quat q, pd_vec3 w, double T, double worst[3],
                   int flags[2])
{
    pd_body b = {0};
    for (int i = 0; i < 3; i++) {
        b.moment[i] = I[i];
        b.inv_moment[i] = 1.0 / I[i];
    }
    pd_state s0 = state_at(v3(0, 0, 1), q, v3(0, 0, 0), w);
    pd_flight f;
    CHECK_STATUS(pd_flight_plan(&b, &s0, G, &f), PD_OK);
    CHECK_INT(f.kind, PD_FLIGHT_ELLIPTIC);
    flags[0] += f.perm[2] == 2;
    flags[1] += f.theta;
    double y[7] = {q.w, q.x, q.y, q.z, w.x, w.y, w.z}, t = 0.0, h = 1e-4;
    for (int i = 1; i <= 20; i++) {
        double Ti = T * i / 20;
        while (t < Ti) {
            double dy[7];
            euler_rhs(t, y, dy, (void *)I);
            if (pd_ode_step_from(ode, euler_rhs, (void *)I, &t, Ti, &h, y, dy) != PD_OK) {
                CHECK(0);
                return;
            }
        }
        pd_state s;
        CHECK_STATUS(pd_flight_eval(&f, Ti, &s), PD_OK);
        double a = quat_angle(s.q, quat_normalize(quat(y[0], y[1], y[2], y[3])));
        double e = v3_dist(s.w, v3(y[4], y[5], y[6])) / v3_norm(w);
        worst[0] = a > worst[0] ? a : worst[0];
        worst[1] = e > worst[1] ? e : worst[1];
        double sc = (a > e ? a : e) * (1.0 - f.m);
        worst[2] = sc > worst[2] ? sc : worst[2];
    }
}

/* The asymmetric top against the ODE reference: random bodies with the
 * polhode about either extreme axis (both orderings of the chart's J), near
 * the separatrix (1 - m down to ~5e-9, nomes up to ~0.65), and nearly symmetric bodies
 * (two moments 1e-3 to 1e-9 apart, n up to 1e9, where the third-kind phase
 * passes close to a zero of theta4). 20 rad/s for 1 s, moments from 1e-8 to
 * 1e-4 kg m^2. Near the separatrix the motion itself is ill-conditioned: the
 * period grows as ln(1/(1 - m)), so a relative change d of the state (its
 * round-off, 1e-16, in either computation) moves the phase after the ~20 rad
 * turned by ~20 d / (1 - m); there the error is bounded times 1 - m. */
static void test_flight_reference(void)
{
    pd_ode *ode = pd_ode_alloc(7, 0.0, 1e-14);
    CHECK(ode != NULL);
    if (!ode)
        return;
    test_rng r = {17};
    double generic[3] = {0}, sep[3] = {0}, sym[3] = {0};
    int gflags[2] = {0}, sflags[2] = {0}, yflags[2] = {0};
    enum { N = 24 };
    for (int i = 0; i < N; i++) {
        double sc = pow(10.0, rng_range(&r, -8.0, -4.0));
        double I[3] = {sc, sc * rng_range(&r, 1.2, 3.0), 0.0};
        I[2] = I[1] * rng_range(&r, 1.2, 3.0);
        pd_quat q = random_quat(&r);
        /* Generic: omega mostly along an extreme axis, so that both charts occur. */
        pd_vec3 d = rng_unit_vector(&r);
        pd_vec3 w = i % 2 ? v3(d.x, d.y, 2.0 * copysign(1.0, d.z) + d.z)
                          : v3(2.0 * copysign(1.0, d.x) + d.x, d.y, d.z);
        vs_ode(ode, I, q, v3_scale(v3_unit(w), 20.0), 1.0, generic, gflags);
        /* Near the separatrix: omega along the middle axis, off by eps. */
        double eps = pow(10.0, -1.0 - (i % 4));
        w = v3(eps * d.x, copysign(1.0, d.y), eps * d.z);
        vs_ode(ode, I, q, v3_scale(v3_unit(w), 20.0), 1.0, sep, sflags);
        /* Nearly symmetric: the middle moment 1e-3 .. 1e-9 from one of the others. */
        double delta = pow(10.0, -3.0 - (i % 7));
        double J[3] = {I[0], i % 2 ? I[0] * (1.0 + delta) : I[2] * (1.0 - delta), I[2]};
        vs_ode(ode, J, q, v3_scale(d, 20.0), 1.0, sym, yflags);
    }
    pd_ode_free(ode);
    pd_note("flight: closed form vs rk8pd at 1e-14, 20 rad/s for 1 s: generic %.1e rad %.1e rel, "
           "nearly symmetric %.1e rad %.1e rel, near the separatrix %.1e rad %.1e rel "
           "(%.1e times 1 - m); theta series in %d, %d, %d of %d\n",
           generic[0], generic[1], sym[0], sym[1], sep[0], sep[1], sep[2], gflags[1], yflags[1],
           sflags[1], N);
    CHECK(gflags[0] > 0 && gflags[0] < N);           /* both charts */
    CHECK(sflags[1] == N); /* off the separatrix itself, always the theta series */
    CHECK(yflags[0] > 0 && yflags[0] < N && yflags[1] > 0);
    CHECK_NEAR(generic[0], 0.0, 1e-12, "ODE reference, its global error ~1e-13");
    CHECK_NEAR(generic[1], 0.0, 1e-12, "ODE reference, its global error ~1e-13");
    CHECK_NEAR(sym[0], 0.0, 1e-12, "ODE reference, its global error ~1e-13");
    CHECK_NEAR(sym[1], 0.0, 1e-12, "ODE reference, its global error ~1e-13");
    CHECK_NEAR(sep[2], 0.0, 1e-14, "ODE reference, 20 rad x round-off 1e-16 / (1 - m) x 5");
    CHECK_NEAR(sep[0], 0.0, 1e-9, "ODE reference; Legendre's forms erred 4e-8 here");
}

/* Lowest vertex height by scanning: the oracle for the impact tests. */
static double scan_height(const pd_body *b, const pd_flight *f, double t)
{
    pd_state s;
    pd_flight_eval(f, t, &s);
    double h = 1e300;
    for (int i = 0; i < b->nverts; i++) {
        double z = pd_body_vertex_world(b, &s, i).z;
        h = z < h ? z : h;
    }
    return h;
}

static void test_impact(void)
{
    pd_part *p = part_of_mesh(mesh_box(0.01, 0.02, 0.03));
    pd_body *b = p ? body_of(p) : NULL;
    if (!b) {
        pd_part_free(p);
        return;
    }
    double L = b->size, tol = PD_TOL_IMPACT_REL * L;
    int contacts[16];
    pd_impact imp;
    pd_flight f;
    /* Flat drop: body axis 3 (largest moment, the 0.03 edge... principal
     * frame) along world z, so a face is horizontal; lowest face at height h. */
    double hz = fabs(b->verts[pd_body_support_scan(b, v3(0, 0, 1))].z);
    double h = 0.12;
    pd_state s0 = {v3(0.0, 0.0, h + hz), quat_identity(), v3(0.05, 0, 0), v3(0, 0, 0)};
    CHECK_STATUS(pd_flight_plan(b, &s0, G, &f), PD_OK);
    CHECK_STATUS(pd_flight_impact(b, &f, 1.0, 0.0, contacts, 16, &imp), PD_OK);
    CHECK_INT(imp.kind, PD_IMPACT_AT);
    double tf = sqrt(2.0 * h / G);
    CHECK_NEAR(imp.t, tf, tol / (G * tf) + 1e-15, "sqrt(2h/g) to the height tolerance / speed");
    CHECK(imp.t <= tf + 1e-15);
    CHECK_INT(imp.ncontacts, 4);
    CHECK(imp.steps <= 3);

    /* Resting on the floor: in contact now. */
    pd_state rest = {v3(0.0, 0.0, hz), quat_identity(), v3(0, 0, 0), v3(0, 0, 0)};
    CHECK_STATUS(pd_flight_plan(b, &rest, G, &f), PD_OK);
    CHECK_STATUS(pd_flight_impact(b, &f, 1.0, 0.0, contacts, 16, &imp), PD_OK);
    CHECK_INT(imp.kind, PD_IMPACT_NOW);
    CHECK_INT(imp.ncontacts, 4);
    /* t_max before the fall ends: no impact. */
    CHECK_STATUS(pd_flight_plan(b, &s0, G, &f), PD_OK);
    CHECK_STATUS(pd_flight_impact(b, &f, 0.5 * tf, 0.0, contacts, 16, &imp), PD_OK);
    CHECK_INT(imp.kind, PD_IMPACT_NONE);

    /* Spinning drops against a fine time scan (dt = 1e-5 s): the search is
     * never later than the first scanned sample below -tol, and at its time
     * the lowest vertex is within tol of the floor. */
    test_rng r = {5};
    for (int trial = 0; trial < 20; trial++) {
        pd_quat q = random_quat(&r);
        pd_vec3 w = v3_scale(rng_unit_vector(&r), rng_range(&r, 5.0, 50.0));
        pd_state st = {v3(0, 0, rng_range(&r, 0.03, 0.15)), q, v3(0.05, 0, rng_range(&r, -0.5, 0.5)), w};
        CHECK_STATUS(pd_flight_plan(b, &st, G, &f), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &f, 1.0, 0.0, contacts, 16, &imp), PD_OK);
        CHECK_INT(imp.kind, PD_IMPACT_AT);
        CHECK_NEAR(scan_height(b, &f, imp.t), 0.0, tol, "impact tolerance");
        double first = 1.0;
        for (double t = 0.0; t < 1.0; t += 1e-5)
            if (scan_height(b, &f, t) < -tol) {
                first = t;
                break;
            }
        CHECK(imp.t <= first);
        CHECK(imp.t > first - 2e-5 * 10); /* and not early: within a few scan steps */
        /* Searched again from part-way along the same flight, at its state
         * there: a contact as valid (within tol of the floor, never after
         * the first crossing), and from the contact itself, touching now. */
        pd_state mid;
        pd_impact again;
        double t0 = 0.5 * imp.t;
        CHECK_STATUS(pd_flight_eval(&f, t0, &mid), PD_OK);
        CHECK_STATUS(pd_flight_impact_from(b, &f, t0, &mid, 0, 1.0, 0.0, contacts, 16, &again), PD_OK);
        CHECK_INT(again.kind, PD_IMPACT_AT);
        CHECK_NEAR(scan_height(b, &f, again.t), 0.0, tol, "impact tolerance");
        CHECK(again.t <= first);
        CHECK_STATUS(pd_flight_eval(&f, imp.t, &mid), PD_OK);
        CHECK_STATUS(pd_flight_impact_from(b, &f, imp.t, &mid, 0, 1.0, 0.0, contacts, 16, &again), PD_OK);
        CHECK_INT(again.kind, PD_IMPACT_NOW);
        CHECK_NEAR(again.t, imp.t, 0.0, "touching at t0: the search stays there");
    }

    /* Skimming: a fast-spinning box released with its lowest corner 1e-5 to
     * 1e-2 L above the floor, the regime of rolling and rocking contact,
     * where the per-vertex step does most of the work (flight_impact.c). The
     * search may never pass the first crossing the scan (dt = 1e-6 s) sees.
     * Its steps are reported: the speed bound alone needed tens. */
    long steps = 0;
    int ntrials = 0;
    for (int trial = 0; trial < 60; trial++) {
        pd_quat q = random_quat(&r);
        pd_vec3 w = v3_scale(rng_unit_vector(&r), rng_range(&r, 10.0, 100.0));
        pd_state st = {v3(0, 0, 0), q, v3(0.1, 0, rng_range(&r, -0.05, 0.05)), w};
        int low = pd_body_support_scan(b, quat_rotate_inv(q, v3(0, 0, 1)));
        st.x.z = -pd_body_vertex_world(b, &st, low).z + L * pow(10.0, rng_range(&r, -5.0, -2.0));
        CHECK_STATUS(pd_flight_plan(b, &st, G, &f), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &f, 0.5, 0.0, contacts, 16, &imp), PD_OK);
        if (imp.kind != PD_IMPACT_AT)
            continue;
        ntrials++;
        steps += imp.steps;
        double first = 0.5;
        for (double t = 0.0; t < imp.t + 1e-5; t += 1e-6)
            if (scan_height(b, &f, t) < -tol) {
                first = t;
                break;
            }
        CHECK(imp.t <= first);
        CHECK_NEAR(scan_height(b, &f, imp.t), 0.0, tol, "impact tolerance");
    }
    CHECK(ntrials > 40);
    pd_note("flight: skimming impact search: %.1f steps on average over %d spinning starts\n",
           ntrials ? (double)steps / ntrials : 0.0, ntrials);

    /* The simultaneity window: the box falling nearly flat (turned 0.5 deg
     * about a diagonal-ish axis) at 1.5 m/s, no spin. A corner belongs to the
     * impact's contact set iff it is within the contact tolerance or its
     * extrapolated height z + z' window is: counted here independently,
     * corner by corner, for windows that take in none, some and all of them. */
    {
        pd_quat q = quat_axis_angle(v3_unit(v3(1.0, 0.3, 0.0)), 0.5 * 3.14159265358979323846 / 180.0);
        int low = pd_body_support_scan(b, quat_rotate_inv(q, v3(0, 0, 1)));
        pd_state st = {v3(0, 0, 0), q, v3(0, 0, -1.5), v3(0, 0, 0)};
        st.x.z = -pd_body_vertex_world(b, &st, low).z + 1e-3;
        const double windows[] = {0.0, 5e-5, 1e-4, 3e-4};
        int counts[4];
        for (int k = 0; k < 4; k++) {
            CHECK_STATUS(pd_flight_plan(b, &st, G, &f), PD_OK);
            CHECK_STATUS(pd_flight_impact(b, &f, 1.0, windows[k], contacts, 16, &imp), PD_OK);
            pd_state at;
            CHECK_STATUS(pd_flight_eval(&f, imp.t, &at), PD_OK);
            int want = 0;
            for (int i = 0; i < b->nverts; i++) {
                double z = pd_body_vertex_world(b, &at, i).z;
                want += z <= PD_TOL_CONTACT_REL * L || z + windows[k] * at.v.z <= PD_TOL_CONTACT_REL * L;
            }
            CHECK_INT(imp.ncontacts, want);
            counts[k] = imp.ncontacts;
        }
        CHECK(counts[0] == 1 && counts[1] < 4 && counts[1] < counts[3] && counts[3] == 4);
        pd_note("flight: contact set of a face landing 0.5 deg off flat, windows 0, 5e-5, 1e-4, 3e-4 s: "
               "%d, %d, %d, %d corners\n", counts[0], counts[1], counts[2], counts[3]);
    }

    /* Grazing: no gravity, no translation; a corner spinning about a
     * horizontal axis dips 1e-4 L below the floor and comes back. The search
     * must find the dip, at the time the scan sees it. */
    {
        pd_vec3 w = v3(0.0, 0.0, 10.0); /* about body axis 3, largest moment */
        pd_quat q = quat_axis_angle(v3(1, 0, 0), 0.5 * 3.14159265358979323846); /* body z -> world -y */
        pd_state st = {v3(0, 0, 0), q, v3(0, 0, 0), w};
        CHECK_STATUS(pd_flight_plan(b, &st, 0.0, &f), PD_OK);
        double lo = 1e300;
        for (double t = 0.0; t < 0.7; t += 1e-4) {
            double z = scan_height(b, &f, t);
            lo = z < lo ? z : lo;
        }
        /* Place the com so that the deepest point is 1e-4 L below the floor. */
        st.x.z = -lo - 1e-4 * L;
        st.q = quat_mul(quat_axis_angle(v3(1, 0, 0), 0.0), st.q);
        CHECK_STATUS(pd_flight_plan(b, &st, 0.0, &f), PD_OK);
        if (scan_height(b, &f, 0.0) > tol) {
            CHECK_STATUS(pd_flight_impact(b, &f, 0.7, 0.0, contacts, 16, &imp), PD_OK);
            CHECK_INT(imp.kind, PD_IMPACT_AT);
            double first = 0.7;
            for (double t = 0.0; t < 0.7; t += 1e-6)
                if (scan_height(b, &f, t) < 0.0) {
                    first = t;
                    break;
                }
            CHECK(imp.t <= first);
            CHECK_NEAR(imp.t, first, 2e-6, "scan step 1e-6 s");
        }
    }
    pd_body_free(b);
    pd_part_free(p);
}

/* A part of 1000 points drawn from r on an ellipsoid of semi-axes 3, 2 and
 * 1 cm, through the library's hull (its facets: triangles); NULL on failure. */
static pd_part *ellipsoid_part(test_rng *r)
{
    enum { N = 1000 };
    pd_vec3 *pts = malloc(sizeof *pts * N);
    for (int i = 0; i < N; i++) {
        pd_vec3 u = rng_unit_vector(r);
        pts[i] = v3(0.03 * u.x, 0.02 * u.y, 0.01 * u.z);
    }
    pd_hull *h = NULL;
    CHECK_STATUS(pd_hull_build(pts, N, &h, NULL), PD_OK);
    pd_part *p = h ? part_of_mesh(mesh_of_hull(h)) : NULL;
    pd_hull_free(h);
    free(pts);
    return p;
}

static void test_support(void)
{
    test_rng r = {3};
    pd_part *p = ellipsoid_part(&r);
    pd_body *b = p ? body_of(p) : NULL;
    if (b) {
        CHECK(b->nverts > 900);
        int hint = 0, bad = 0;
        double worst = 0.0;
        for (int i = 0; i < 2000; i++) {
            pd_vec3 d = rng_unit_vector(&r);
            hint = i % 2 ? hint : (int)(rng_next(&r) % (uint64_t)b->nverts);
            hint = pd_body_support(b, d, hint);
            int ref = pd_body_support_scan(b, d);
            double e = v3_dot(d, b->verts[hint]) - v3_dot(d, b->verts[ref]);
            worst = e > worst ? e : worst;
            bad += e > 1e-15 * b->size;
        }
        CHECK_NEAR(worst / b->size, 0.0, 1e-15, "hill-climb = scan, round-off");
        CHECK_INT(bad, 0);
    }
    pd_body_free(b);
    pd_part_free(p);
}

/* The impact search's bound on the angular acceleration, |dw/dt| <=
 * spin_accel |w|^2, against Euler's equations (rk4_deriv) at random w: never
 * exceeded beyond the ratios' round-off (1e-12), approached within 15% (the
 * bound's worst case, one ratio dominating, reaches sqrt(3)/2 = 0.866 of it,
 * and so do the random draws), and 0 for a cube. */
static void test_spin_accel(void)
{
    pd_mesh *meshes[3] = {mesh_box(0.01, 0.02, 0.03), mesh_prism(32, 0.01, 0.002), mesh_box(0.01, 0.01, 0.01)};
    test_rng r = {29};
    for (int k = 0; k < 3; k++) {
        pd_part *p = part_of_mesh(meshes[k]);
        pd_body *b = body_or_free(p);
        if (!b)
            continue;
        double worst = 0.0;
        for (int i = 0; i < 20000; i++) {
            pd_vec3 w = v3_scale(rng_unit_vector(&r), rng_range(&r, 0.1, 100.0)), dw;
            pd_quat dq;
            rk4_deriv(b, quat_identity(), w, &dq, &dw);
            worst = worse(worst, v3_norm(dw) / v3_dot(w, w));
        }
        CHECK(worst <= b->spin_accel * (1.0 + 1e-12));
        if (k < 2)
            CHECK(worst >= 0.85 * b->spin_accel);
        else
            CHECK_NEAR(b->spin_accel, 0.0, 0.0, "equal moments, snapped");
        pd_body_free(b);
        pd_part_free(p);
    }
}

/* The polish at the end of the hill-climb is skipped where the facets around
 * the answer are flat (PD_TOL_SUPPORT_FLAT_REL), and must still run where
 * they are bent: a 32-gon prism with exact coordinates needs it nowhere, the
 * same prism with its points moved at random by up to 3e-8 L (still merged:
 * PD_TOL_PLANE_REL) needs it.
 * Directions within 1e-6 rad of a cap's normal are where a bent cap hides a
 * lower corner behind a diagonal; there and anywhere the hill-climb must
 * find the scan's vertex, from any start. */
/* A 32-gon prism with exact coordinates, and the same with its points moved
 * at random by up to 3e-8 L (ring_spec's noise is in units of
 * PD_TOL_SYMMETRY_REL L), below PD_TOL_PLANE_REL, so its caps still merge. */
static const ring_spec EXACT_PRISM = {32, 0, 0.0, 0.0, 0.0, 0, 0};
static const ring_spec BENT_PRISM = {32, 0, 0.0, 0.0, 3e-8 / PD_TOL_SYMMETRY_REL, 0, 0};

static void test_support_flat(void)
{
    for (int bent = 0; bent < 2; bent++) {
        pd_part *p = ring_part(bent ? &BENT_PRISM : &EXACT_PRISM, NULL, 1.0, v3(0, 0, 0));
        pd_body *b = body_or_free(p);
        if (!b)
            continue;
        CHECK_INT(b->nverts, 64);
        int marked = 0;
        for (int i = 0; i < b->nverts; i++)
            marked += b->polish[i];
        if (bent)
            CHECK(marked > 0);
        else
            CHECK_INT(marked, 0);
        pd_vec3 axis = quat_rotate_inv(b->frame, v3(0, 0, 1)); /* the caps' normal, body frame */
        test_rng r = {21};
        double worst = 0.0;
        for (int i = 0; i < 4000; i++) {
            pd_vec3 tilt = v3_scale(rng_unit_vector(&r), i % 2 ? 1e-6 : 1.0);
            pd_vec3 d = v3_unit(v3_add(i % 4 < 2 ? axis : v3_neg(axis), tilt));
            int v = pd_body_support(b, d, (int)(rng_next(&r) % (uint64_t)b->nverts));
            double e = v3_dot(d, b->verts[v]) - v3_dot(d, b->verts[pd_body_support_scan(b, d)]);
            worst = worse(worst, e);
        }
        CHECK_NEAR(worst / b->size, 0.0, 1e-15, "hill-climb = scan, round-off");
        pd_body_free(b);
        pd_part_free(p);
    }
}

/* The positive root of z + dz D - B D^2 / 2 (z > 0, B >= 0), each form
 * where it does not cancel; HUGE_VAL when there is none. */
static double first_root(double z, double dz, double B)
{
    double sq = sqrt(dz * dz + 2.0 * B * z);
    return dz < 0.0 ? 2.0 * z / (sq - dz) : B > 0.0 ? (dz + sq) / B : HUGE_VAL;
}

/* The impact search's per-vertex step, hill-climbed, against every vertex's
 * root computed in the world frame: on a box, a 32-gon prism (exact and bent)
 * and a 1000-point ellipsoid, spinning up to 100 rad/s at 1e-6 to 0.1 L above
 * the floor, from random start vertices. */
static void test_vertex_step(void)
{
    test_rng r = {13};
    pd_part *parts[4] = {part_of_mesh(mesh_box(0.01, 0.02, 0.03)), ring_part(&EXACT_PRISM, NULL, 1.0, v3(0, 0, 0)),
                         ring_part(&BENT_PRISM, NULL, 1.0, v3(0, 0, 0)), ellipsoid_part(&r)};
    for (int k = 0; k < 4; k++) {
        pd_body *b = body_or_free(parts[k]);
        if (!b)
            continue;
        double worst = 0.0;
        for (int trial = 0; trial < 500; trial++) {
            pd_quat q = random_quat(&r);
            double wn = trial % 10 ? rng_range(&r, 0.0, 100.0) : 0.0;
            pd_state s = {v3(0, 0, 0), q, v3(0.1, 0, rng_range(&r, -2.0, 1.0)),
                          v3_scale(rng_unit_vector(&r), wn)};
            double gap = b->size * pow(10.0, rng_range(&r, -6.0, -1.0));
            lift(b, &s, gap);
            /* A valid bound of the search's form, g + (1 + k) wmax^2 rmax
             * with k = 1 >= spin_accel (at most 1/sqrt 3); without gravity
             * in one trial in 20. */
            double B = (trial % 20 ? G : 0.0) + 2.0 * wn * wn * b->rmax;
            double want = HUGE_VAL;
            pd_vec3 ww = quat_rotate(s.q, s.w);
            for (int i = 0; i < b->nverts; i++) {
                pd_vec3 rel = quat_rotate(s.q, b->verts[i]);
                double z = s.x.z + rel.z, dz = s.v.z + v3_cross(ww, rel).z;
                double root = first_root(z, dz, B);
                want = root < want ? root : want;
            }
            double got = pd_flight_vertex_step(b, &s, B, (int)(rng_next(&r) % (uint64_t)b->nverts));
            /* The heights carry round-off ~1e-16 L: relative to the gap in the root. */
            double e = want < HUGE_VAL ? fabs(got - want) / want * gap / b->size : (got < HUGE_VAL ? 1.0 : 0.0);
            worst = worse(worst, e);
        }
        CHECK_NEAR(worst, 0.0, 1e-14, "smallest root over all vertices, heights' round-off");
        pd_body_free(b);
        pd_part_free(parts[k]);
    }
}

/* The impact search's curvature step (flight_impact.c). Its bound first:
 * along the closed-form flight, every vertex of a box, a 32-gon coin, a cube
 * (no angular acceleration) and a 1000-point ellipsoid, spinning up to
 * 100 rad/s, stays above its Taylor polynomial of degree 2 at the sample
 * (derivatives from Euler's equations in the world frame) less C D^3 / 6, up
 * to rotations of 1 rad; and C is not loose by more than a factor of 20 on
 * the worst of them. Then the step: the smallest root over all vertices of
 * the quadratics it takes, capped at H, computed here vertex by vertex in the
 * world frame, from random start vertices. */
static void test_curvature_step(void)
{
    test_rng r = {17};
    pd_part *parts[4] = {part_of_mesh(mesh_box(0.01, 0.02, 0.03)), part_of_mesh(mesh_prism(32, 0.01, 0.002)),
                         part_of_mesh(mesh_box(0.01, 0.01, 0.01)), ellipsoid_part(&r)};
    double worst_below = 0.0, tightest = 0.0, worst_step = 0.0;
    long eval_failed = 0;
    for (int k = 0; k < 4; k++) {
        pd_body *b = body_or_free(parts[k]);
        if (!b)
            continue;
        double kk = b->spin_accel;
        for (int trial = 0; trial < 200; trial++) {
            pd_quat q = random_quat(&r);
            double wn = rng_range(&r, 1.0, 100.0);
            pd_state s = {v3(0, 0, 0), q, v3(0.1, 0, rng_range(&r, -2.0, 1.0)),
                          v3_scale(rng_unit_vector(&r), wn)};
            double gap = b->size * pow(10.0, rng_range(&r, -6.0, -1.0));
            lift(b, &s, gap);
            pd_flight f;
            CHECK_STATUS(pd_flight_plan(b, &s, G, &f), PD_OK);
            double H = rng_range(&r, 0.01, 1.0) / f.wmax;
            double C = (1.0 + 3.0 * kk + 3.0 * kk * kk) * f.wmax * f.wmax * f.wmax * b->rmax;
            pd_vec3 dw;
            pd_quat dq;
            rk4_deriv(b, s.q, s.w, &dq, &dw);
            pd_vec3 ww = quat_rotate(s.q, s.w), aw = quat_rotate(s.q, dw);
            pd_vec3 up = quat_rotate_inv(s.q, v3(0, 0, 1));
            pd_vec3 c = v3_add(v3_cross(v3_cross(up, s.w), s.w), v3_cross(up, dw));
            double B0 = fmax(G + C * H / 3.0, v3_norm(c) * b->rmax);
            double want = H;
            for (int i = 0; i < b->nverts; i++) {
                pd_vec3 rel = quat_rotate(s.q, b->verts[i]);
                double z = s.x.z + rel.z, dz = s.v.z + v3_cross(ww, rel).z;
                double ddz = -G + v3_add(v3_cross(aw, rel), v3_cross(ww, v3_cross(ww, rel))).z;
                double root = first_root(z, dz, fmax(B0 - (ddz + G), 0.0));
                want = root < want ? root : want;
                if (i % 3 == 0)
                    for (int j = 1; j <= 16; j++) {
                        double D = H * j / 16.0;
                        pd_state at;
                        if (pd_flight_eval(&f, D, &at) != PD_OK) {
                            eval_failed++;
                            continue;
                        }
                        double zt = pd_body_vertex_world(b, &at, i).z;
                        double taylor = z + dz * D + 0.5 * ddz * D * D, cubic = C * D * D * D / 6.0;
                        worst_below = worse(worst_below, (taylor - cubic - zt) / b->size);
                        tightest = worse(tightest, (taylor - zt) / cubic);
                    }
            }
            double got = pd_flight_curvature_step(b, &s, G, f.wmax, H, (int)(rng_next(&r) % (uint64_t)b->nverts));
            /* The heights carry round-off ~1e-16 L: relative to the gap in the root. */
            worst_step = worse(worst_step, fabs(got - want) / want * gap / b->size);
        }
        pd_body_free(b);
        pd_part_free(parts[k]);
    }
    CHECK_INT(eval_failed, 0);
    CHECK_NEAR(worst_below, 0.0, 1e-14, "never below the bound, the flight's round-off");
    CHECK(tightest <= 1.0 && tightest > 0.05);
    CHECK_NEAR(worst_step, 0.0, 1e-14, "smallest root over all vertices, heights' round-off");
    pd_note("flight: curvature bound: the worst vertex used %.2f of its C D^3 / 6\n", tightest);
}

/* ulps of |y|'s binade, for the sine and cosine. */
static double ulp_of(double y)
{
    return nextafter(fabs(y), INFINITY) - fabs(y);
}

/* The flight's sine and cosine against libm's (within half an ulp): where
 * the value exceeds 1e-3, within 1.5 ulp (sincos.h measures 0.92 against long
 * double, libm's 0.52); everywhere within 2e-16 absolutely (the reduction's
 * 7e-22, near multiples of pi/2 too). Angles to 1e5, their near multiples of
 * pi/2 and libm's own beyond (1e6, and NaN). */
static void test_sincos(void)
{
    test_rng r = {29};
    double worst_ulp = 0.0, worst_abs = 0.0;
    for (int i = 0; i < 100000; i++) {
        double range = i % 3 == 0 ? 0.8 : i % 3 == 1 ? 10.0 : 1e5;
        double x = rng_range(&r, -range, range), s, c;
        if (i % 5 == 0)
            x = floor(x) * (0.5 * M_PI) + rng_range(&r, -1e-9, 1e-9);
        pd_sincos(x, &s, &c);
        double S = sin(x), C = cos(x);
        double e = fmax(fabs(s - S), fabs(c - C));
        worst_abs = worse(worst_abs, e);
        if (fabs(S) > 1e-3 && fabs(C) > 1e-3) {
            e = fmax(fabs(s - S) / ulp_of(S), fabs(c - C) / ulp_of(C));
            worst_ulp = worse(worst_ulp, e);
        }
    }
    CHECK_NEAR(worst_ulp, 0.0, 1.5, "0.92 ulp + libm's 0.52 (sincos.h)");
    CHECK_NEAR(worst_abs, 0.0, 2e-16, "an ulp of 1, round-off");
    double s, c;
    pd_sincos(1e6, &s, &c);
    CHECK(s == sin(1e6) && c == cos(1e6));
    pd_sincos(NAN, &s, &c);
    CHECK(isnan(s) && isnan(c));
}

/* The flight's bound on |w| (wmax): never below |w| anywhere along the
 * torque-free motion, sampled at 2000 times over ten turns, for boxes from
 * a cube to a 1000 : 1 needle and random states; and tight where the
 * inertia ratio is extreme: for a needle turning end over end the bound must
 * be within 1e-3 of the largest |w| sampled (the classical |L| / I_min was
 * 5e5 times it, and the impact search ran out of steps). */
/* The plan in two halves (pd_flight_plan_bounds, then pd_flight_complete
 * when the search first evaluates the flight) is the same flight: random
 * spinning boxes, searched from a bounds-only plan and from a whole one,
 * give the same contact to the bit and, evaluated anywhere, the same state;
 * a search that finds the part touching at once leaves the rotation
 * unsolved, and a bounds-only flight refuses evaluation away from t = 0. */
static void test_plan_halves(void)
{
    pd_part *p = part_of_mesh(mesh_box(0.01, 0.02, 0.03));
    pd_body *b = p ? body_of(p) : NULL;
    if (!b) {
        pd_part_free(p);
        return;
    }
    test_rng r = {41};
    int contacts[16], same = 1, trials = 0;
    for (int trial = 0; trial < 40; trial++) {
        pd_quat q = random_quat(&r);
        pd_vec3 w = v3_scale(rng_unit_vector(&r), rng_range(&r, 1.0, 50.0));
        pd_state st = {v3(0, 0, rng_range(&r, 0.02, 0.1)), q, v3(0.05, 0, -0.2), w};
        pd_flight whole, half;
        pd_impact a, c;
        CHECK_STATUS(pd_flight_plan(b, &st, G, &whole), PD_OK);
        CHECK_STATUS(pd_flight_plan_bounds(b, &st, G, &half), PD_OK);
        CHECK_INT(half.kind, PD_FLIGHT_BOUNDS); /* the box's moments all differ */
        pd_state at;
        CHECK_STATUS(pd_flight_eval(&half, 1e-3, &at), PD_ERR_USAGE);
        CHECK_STATUS(pd_flight_eval(&half, 0.0, &at), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &whole, 1.0, 0.0, contacts, 16, &a), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &half, 1.0, 0.0, contacts, 16, &c), PD_OK);
        CHECK_INT(c.kind, PD_IMPACT_AT);
        CHECK_INT(half.kind, whole.kind);
        same &= a.kind == c.kind && a.t == c.t && a.vertex == c.vertex && a.height == c.height &&
                a.steps == c.steps;
        for (int i = 1; i <= 4; i++) {
            pd_state x, y;
            CHECK_STATUS(pd_flight_eval(&whole, a.t * i / 4.0, &x), PD_OK);
            CHECK_STATUS(pd_flight_eval(&half, a.t * i / 4.0, &y), PD_OK);
            same &= memcmp(&x, &y, sizeof x) == 0;
        }
        /* At its contact: touching now, and nothing solved. */
        pd_state touch;
        CHECK_STATUS(pd_flight_eval(&whole, a.t, &touch), PD_OK);
        CHECK_STATUS(pd_flight_plan_bounds(b, &touch, G, &half), PD_OK);
        CHECK_STATUS(pd_flight_impact(b, &half, 1.0, 0.0, contacts, 16, &c), PD_OK);
        CHECK_INT(c.kind, PD_IMPACT_NOW);
        CHECK_INT(half.kind, PD_FLIGHT_BOUNDS);
        CHECK_STATUS(pd_flight_complete(b, &half), PD_OK);
        CHECK_INT(half.kind, PD_FLIGHT_ELLIPTIC);
        trials++;
    }
    CHECK(same); /* the same arithmetic in the same order: bit for bit */
    CHECK_INT(trials, 40);
    pd_body_free(b);
    pd_part_free(p);
}

static void test_wmax(void)
{
    test_rng r = {29};
    const double aspect[] = {1.0, 3.0, 30.0, 300.0, 1000.0};
    double worst_over = 0.0, needle_ratio = 0.0;
    for (int k = 0; k < 5; k++) {
        pd_part *part = part_of_mesh(mesh_box(1.0, 1.3 / aspect[k], 1.0 / aspect[k]));
        pd_body *b = body_or_free(part);
        if (!b)
            continue;
        for (int trial = 0; trial < 40; trial++) {
            pd_state s = {v3(0, 0, 1), random_quat(&r), v3(0, 0, 0),
                          v3_scale(rng_unit_vector(&r), rng_range(&r, 0.1, 10.0))};
            pd_flight f;
            CHECK_STATUS(pd_flight_plan(b, &s, G, &f), PD_OK);
            double T = 10.0 * 2.0 * M_PI / fmax(v3_norm(s.w), 1e-300);
            for (int i = 0; i <= 2000; i++) {
                pd_state at;
                if (pd_flight_eval(&f, T * i / 2000.0, &at) != PD_OK) {
                    CHECK(0);
                    break;
                }
                worst_over = fmax(worst_over, v3_norm(at.w) / f.wmax - 1.0);
            }
        }
        if (k == 4) {
            /* End over end: w across the long axis (the body's x, smallest
             * moment) with a little spin about it; the bound against the
             * largest |w| sampled. */
            pd_state s = {v3(0, 0, 1), quat(1, 0, 0, 0), v3(0, 0, 0), v3(0.5, 3.0, 0.1)};
            pd_flight f;
            CHECK_STATUS(pd_flight_plan(b, &s, G, &f), PD_OK);
            double wbig = 0.0, T = 10.0 * 2.0 * M_PI / v3_norm(s.w);
            for (int i = 0; i <= 20000; i++) {
                pd_state at;
                if (pd_flight_eval(&f, T * i / 20000.0, &at) == PD_OK)
                    wbig = fmax(wbig, v3_norm(at.w));
            }
            needle_ratio = f.wmax / wbig;
        }
        pd_body_free(b);
        pd_part_free(part);
    }
    /* The motion's own |w| is computed to ~1e-12 (the flight's series). */
    CHECK(worst_over <= 1e-9);
    CHECK(needle_ratio >= 1.0 && needle_ratio <= 1.0 + 1e-3);
    pd_note("flight: wmax: |w| / bound - 1 at most %.2g; needle bound / largest |w| %.9g\n", worst_over,
           needle_ratio);
}

void suite_flight(void)
{
    test_sincos();
    test_eigen();
    test_flight();
    test_flight_reference();
    test_impact();
    test_plan_halves();
    test_support();
    test_spin_accel();
    test_support_flat();
    test_vertex_step();
    test_curvature_step();
    test_wmax();
}
