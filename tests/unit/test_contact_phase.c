/* test_contact_phase.c: sustained contact as a continuous motion: closed
 * forms for a box sliding along an edge and toppling about one, energy that
 * never rises, and a hand-over that leaves no vertex below the floor. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "contact/contact_phase.h"
#include "drop_fixture.h"
#include "base/gsl_adapter.h"
#include "contact/phase_forces.h"
#include "contact/contact_tol.h"
#include "base/quat.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

static const double G = 9.81;

/* Body-frame half extents of a box body. */
static pd_vec3 half_extents(const pd_body *b)
{
    pd_vec3 e = v3(0, 0, 0);
    for (int i = 0; i < b->nverts; i++)
        e = v3(fmax(e.x, fabs(b->verts[i].x)), fmax(e.y, fabs(b->verts[i].y)),
               fmax(e.z, fabs(b->verts[i].z)));
    return e;
}

/* The box standing on its edge along body x at (y, z) = (-Y, -Z), turned
 * about x so that the arm from the edge to the centre of mass leans `tilt`
 * rad past the vertical, the edge on the floor, at rest. */
static pd_state on_edge(const pd_body *b, double tilt, int *contacts, int *nc)
{
    pd_vec3 h = half_extents(b);
    double a = atan2(h.y, h.z) + tilt;
    pd_state s = {v3(0, 0, 0), quat_axis_angle(v3(1, 0, 0), a), v3(0, 0, 0), v3(0, 0, 0)};
    *nc = lowest_vertices(b, s.q, contacts);
    s.x.z = -quat_rotate(s.q, b->verts[contacts[0]]).z;
    return s;
}

/* The 1 x 2 x 3 cm box with friction mu on its long edge (on_edge), leaning
 * tilt past balance or, where face_gap > 0, until its side face is face_gap
 * rad above the floor: its body and state, or NULL (torn down) where the
 * setup or the edge fails. */
static const pd_body *box_on_edge(drop_fixture *fx, pd_scene *sc, double mu, double tilt,
                                  double face_gap, pd_state *s, int *contacts)
{
    const pd_body *b = drop_setup_box(fx, sc, mu);
    if (!b)
        return NULL;
    int nc;
    pd_vec3 h = half_extents(b);
    if (face_gap > 0.0)
        tilt = 0.5 * M_PI - face_gap - atan2(h.y, h.z);
    *s = on_edge(b, tilt, contacts, &nc);
    CHECK_INT(nc, 2);
    if (nc != 2) {
        drop_teardown(fx);
        return NULL;
    }
    return b;
}

/* The edge phase started at s (contacts[0..2)): admitted, both ends
 * sliding, the first from rest and the second too where both_rest. 1 if
 * started. */
static int edge_slide_starts(const drop_fixture *fx, const pd_scene *sc, pd_state *s,
                             const int *contacts, pd_phase *phase, int both_rest)
{
    int started = pd_contact_phase_start(&fx->model->settle, sc, s, contacts, 2, phase);
    CHECK(started);
    if (!started)
        return 0;
    CHECK_INT(phase->nc, 2);
    CHECK(phase->mode[0] == PD_PHASE_SLIDE && phase->mode[1] == PD_PHASE_SLIDE);
    CHECK(phase->from_rest[0] && phase->from_rest[1] == both_rest);
    return 1;
}

/* Sliding along the edge, balanced over it: friction mu m g brakes the box
 * along x and its pitching moment is carried by the two ends' normal forces
 * (mu h < X, so both stay positive); nothing turns. Closed form until the
 * slip falls to the phase's end threshold: v = v0 - mu g t,
 * x = v0 t - mu g t^2 / 2. */
static void test_edge_slide(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    int contacts[8], nc;
    pd_state s = on_edge(b, 0.0, contacts, &nc);
    CHECK_INT(nc, 2);
    double v0 = 0.2, z0 = s.x.z, L = b->size;
    s.v = v3(v0, 0, 0);
    pd_phase phase;
    CHECK(pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &phase));
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    double t = 0.0;
    CHECK_STATUS(pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &phase, &s, 1.0, &t), PD_OK);
    /* It hands over as the slip falls to the end threshold, at most the
     * event tolerance early; late only by the ODE error of the slip
     * (1e-8 v0, above), 1e-8 sqrt(L/g) in time. The motion is quadratic in
     * t, which the integrator's pair follows to round-off: measured 2e-17. */
    double T = sqrt(L / G), slip_min = PD_TOL_PHASE_SLIP_REL * sqrt(G * L);
    double stop = (v0 - slip_min) / (sc.mu * G);
    CHECK(t <= stop + 1e-8 * T);
    CHECK(t >= stop - (PD_TOL_PHASE_EVENT_REL + 1e-8) * T);
    CHECK_NEAR(s.v.x, v0 - sc.mu * G * t, 1e-8 * v0, "closed form, exact for the pair");
    CHECK_NEAR(s.x.x, v0 * t - 0.5 * sc.mu * G * t * t, 1e-9 * L, "closed form, exact for the pair");
    CHECK_NEAR(s.x.z, z0, 1e-9 * L, "balanced over the edge: the height holds");
    CHECK_NEAR(v3_norm(s.w), 0.0, 1e-6, "no turn: measured 0, the balanced start excites none (the balance's instability would grow a turn ~12x)");
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* Turning about a fixed edge: the rate at turn a (about body x) from the
 * energy, w^2 = w0^2 + 2 m g (zc(a0) - zc(a)) / I_e, zc(a) = Y sin a +
 * Z cos a the centre's height above the edge; 1 / w is the time per
 * radian. */
typedef struct {
    double w0sq, k, Y, Z, a0;
} topple_rate;

static double topple_dt_da(double a, void *user)
{
    const topple_rate *r = user;
    double zc0 = r->Y * sin(r->a0) + r->Z * cos(r->a0), zc = r->Y * sin(a) + r->Z * cos(a);
    return 1.0 / sqrt(r->w0sq + r->k * (zc0 - zc));
}

/* Toppling about the edge: started 0.05 rad short of balance and turning
 * towards it with `excess` times the energy it needs to pass, and friction
 * enough to hold the edge. A rotation about a fixed axis: the reaction
 * does no work, the energy is conserved, the edge does not move, and the
 * box turns about the edge at w = sqrt(w0^2 + 2 m g dh / I_e). With excess
 * above 1 (1.5: the outcome open, a part leaning past balance from rest
 * being decided at once, which ends an integrated phase) the next face
 * comes down at a = pi/2; below 1 the box turns back short of balance and
 * its own face comes down again at a = 0, by the quadrature of dt/da up to
 * the turn and back (its 1 / sqrt singularity at the turn is QAGS's to
 * take). The pivot (contact_pivot.c) runs it in closed form and must meet
 * the exact solution to round-off: energy to 1e-12 m g L (measured 1e-16),
 * the edge fixed to 1e-12 L (on its axis by construction), the rate the
 * energy gives to 1e-10 of it (measured 6e-16) and the hand-over exactly
 * half the event tolerance before the landing, to 1e-9 sqrt(L/g) (the
 * elliptic integral's round-off and the landing's angle, located to
 * PD_TOL_PIVOT_ANGLE; measured 3e-13). */
static void edge_topple(const drop_fixture *fx, const pd_scene *sc, const pd_body *b,
                        pd_ode *ode, pd_ode *pivot, double lean, double excess)
{
    int contacts[8], nc;
    pd_state s = on_edge(b, -lean, contacts, &nc);
    CHECK_INT(nc, 2);
    pd_vec3 h = half_extents(b);
    double Ie = b->moment[0] + b->mass * (h.y * h.y + h.z * h.z), L = b->size, T = sqrt(L / G);
    double w0 = sqrt(excess * 2.0 * b->mass * G * (hypot(h.y, h.z) - s.x.z) / Ie);
    pd_vec3 e0 = v3_add(s.x, quat_rotate(s.q, b->verts[contacts[0]]));
    s.w = v3(w0, 0, 0);
    s.v = v3_cross(quat_rotate(s.q, s.w), v3_sub(s.x, e0)); /* the edge at rest */
    double E0 = total_energy(b, G, &s), z0 = s.x.z;
    pd_phase phase;
    CHECK(pd_contact_phase_start(&fx->model->settle, sc, &s, contacts, nc, &phase));
    CHECK_NEAR(total_energy(b, G, &s), E0, 1e-12 * E0, "already on the constraint: the start changes nothing");
    double t = 0.0;
    CHECK_STATUS(pd_contact_phase(&fx->model->settle, ode, pivot, sc, &phase, &s, 1.0, &t), PD_OK);
    CHECK(t > 0.0);
    double dE = fabs(total_energy(b, G, &s) - E0) / (b->mass * G * L);
    CHECK_NEAR(dE, 0.0, 1e-8, "conservation: the ODE error alone, measured 3.7e-9 m g L at 1e-8 per step");
    pd_vec3 e1 = v3_add(s.x, quat_rotate(s.q, b->verts[contacts[0]]));
    double moved = v3_norm(v3_sub(e1, e0)) / L;
    CHECK_NEAR(moved, 0.0, 1e-8, "a sticking contact stays put: ODE error, measured 7.7e-9 L");
    /* It ends as the next face lands: some other vertex at the floor. */
    double low = 1e300;
    for (int i = 0; i < b->nverts; i++)
        if (i != contacts[0] && i != contacts[1])
            low = fmin(low, s.x.z + quat_rotate(s.q, b->verts[i]).z);
    CHECK_NEAR(low, 0.0, 1e-5 * L, "event located to 1e-6 sqrt(L/g), arriving at a few sqrt(g L): a few 1e-6 L");
    /* The time to the landing by quadrature of dt/da. The phase hands over
     * at most the event tolerance early, late only by the ODE error. */
    topple_rate rate = {w0 * w0, 2.0 * b->mass * G / Ie, h.y, h.z, atan2(h.y, h.z) - lean};
    double t_land;
    if (excess > 1.0) {
        CHECK_STATUS(pd_quad_integrate(topple_dt_da, &rate, rate.a0, 0.5 * M_PI, 1e-13, &t_land), PD_OK);
    } else {
        /* The turn: zc = H sin(a + beta) reaches zc(a0) + w0^2 / k. */
        double H = hypot(h.y, h.z), beta = atan2(h.z, h.y);
        double zc0 = h.y * sin(rate.a0) + h.z * cos(rate.a0);
        double a_turn = asin((zc0 + rate.w0sq / rate.k) / H) - beta, up, down;
        CHECK_STATUS(pd_quad_integrate(topple_dt_da, &rate, rate.a0, a_turn, 1e-13, &up), PD_OK);
        CHECK_STATUS(pd_quad_integrate(topple_dt_da, &rate, 0.0, a_turn, 1e-13, &down), PD_OK);
        t_land = up + down;
    }
    CHECK(t <= t_land + 1e-8 * T);
    CHECK(t >= t_land - (PD_TOL_PHASE_EVENT_REL + 1e-8) * T);
    double w = sqrt(w0 * w0 + 2.0 * b->mass * G * (z0 - s.x.z) / Ie);
    CHECK_NEAR(fabs(s.w.x), w, 1e-7 * w, "energy about a fixed axis: ODE error, measured 7.6e-8 w");
    CHECK_NEAR(hypot(s.w.y, s.w.z), 0.0, 1e-7 * w, "the axis is the edge (pivot: by construction)");
    if (pivot) {
        CHECK_NEAR(dE, 0.0, 1e-12, "closed form: energy exact but for round-off");
        CHECK_NEAR(moved, 0.0, 1e-12, "closed form: the edge is the axis");
        CHECK_NEAR(fabs(s.w.x), w, 1e-10 * w, "closed form: the rate the energy gives");
        CHECK_NEAR(t, t_land - 0.5 * PD_TOL_PHASE_EVENT_REL * T, 1e-9 * T,
                   "closed form: half the event tolerance before the landing");
        pd_note("contact_phase: pivot in closed form, excess %.1f: energy %.1e m g L, rate %.1e, "
                "hand-over %.1e sqrt(L/g) off\n",
                excess, dE, fabs(fabs(s.w.x) - w) / w,
                fabs(t - (t_land - 0.5 * PD_TOL_PHASE_EVENT_REL * T)) / T);
    }
}

/* Both ways the phase can run it: the full 13-unknown motion (no pivot
 * integrator), whose ODE error the tolerances above were measured on, and
 * the pivot (contact_pivot.c), which a drop takes for two sticking
 * contacts; the pivot also where it turns back, 0.5 rad above its face
 * with a fifth of the energy to balance (the integrated phase would end
 * there as the energy test decides the drop), with friction 5: at 1 the
 * edge starts to slip on the way down, which ends the phase before the
 * landing. */
static void test_edge_topple(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 1.0);
    if (!b)
        return;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    edge_topple(&fx, &sc, b, ode, NULL, 0.05, 1.5);
    edge_topple(&fx, &sc, b, ode, pivot, 0.05, 1.5);
    sc.mu = 5.0;
    edge_topple(&fx, &sc, b, ode, pivot, 0.5, 0.2);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* A random state of body b touching the floor at its lowest vertices
 * contacts (their count returned), sliding at up to 0.5 m/s and spinning
 * at up to 20 rad/s, the first contact moving along the floor, not into or
 * out of it; a random friction coefficient in sc. */
static int random_contact(const pd_body *b, test_rng *rng, pd_scene *sc, pd_state *s,
                          int *contacts)
{
    double r[3][3];
    rng_rotation(rng, r);
    sc->mu = rng_range(rng, 0.1, 1.0);
    *s = (pd_state){v3(0, 0, 0), quat_normalize(quat_from_matrix(CR(r))),
                    v3(rng_range(rng, -0.5, 0.5), rng_range(rng, -0.5, 0.5), 0.0),
                    v3_scale(rng_unit_vector(rng), rng_range(rng, 0.0, 20.0))};
    int nc = lowest_vertices(b, s->q, contacts);
    s->x.z = -quat_rotate(s->q, b->verts[contacts[0]]).z;
    s->v.z = -v3_cross(quat_rotate(s->q, s->w), quat_rotate(s->q, b->verts[contacts[0]])).z;
    return nc;
}

/* Random phases of a box on a vertex or an edge, sliding and spinning: the
 * start (a projection) and the phase never add energy beyond the
 * integration error, and the hand-over leaves every other vertex above the
 * contacts. */
static void test_random_phases(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    double L = b->size, mgL = b->mass * G * L;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    test_rng rng = {31};
    int started = 0, rises = 0, below = 0;
    for (int k = 0; k < 300; k++) {
        pd_state s;
        int contacts[8], nc = random_contact(b, &rng, &sc, &s, contacts);
        double E0 = total_energy(b, G, &s);
        pd_phase phase;
        if (!pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &phase))
            continue;
        started++;
        double E1 = total_energy(b, G, &s), t;
        rises += E1 > E0 + 1e-14 * mgL;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &phase, &s, 0.5, &t) != PD_OK)
            continue;
        rises += total_energy(b, G, &s) > E1 + 1e-8 * mgL;
        double floor_z = 1e300, low = 1e300;
        for (int i = 0; i < nc; i++)
            floor_z = fmin(floor_z, s.x.z + quat_rotate(s.q, b->verts[contacts[i]]).z);
        for (int i = 0; i < b->nverts; i++)
            if (i != contacts[0] && (nc < 2 || i != contacts[1]))
                low = fmin(low, s.x.z + quat_rotate(s.q, b->verts[i]).z);
        below += low < floor_z - 1e-12 * L;
    }
    CHECK(started >= 100);
    CHECK_INT(rises, 0);
    CHECK_INT(below, 0);
    pd_note("contact_phase: %d of 300 random sliding or spinning contacts started a phase\n", started);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* The velocity of body vertex v of state s (world; s.w is body frame). */
static pd_vec3 contact_speed(const pd_body *b, const pd_state *s, int v)
{
    return v3_add(s->v, quat_rotate(s->q, v3_cross(s->w, b->verts[v])));
}

/* A start near the slip threshold: the phase's modes are those its start
 * projected for, so every sticking contact starts at rest, and every sliding
 * one above the end threshold or, sliding from rest where it cannot stick,
 * at rest; the energy never rises in the phase. The
 * box on a vertex or an edge, at random or on an edge at a random tilt
 * (where the other end of the edge moves normally), its velocities scaled so that the
 * first contact slips at 0.5-4 times the end threshold, where the start's
 * projection can carry a slip across the start threshold (2x). */
static void test_start_modes(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.5);
    if (!b)
        return;
    double L = b->size, V0 = sqrt(G * L), mgL = b->mass * G * L;
    double slip_min = PD_TOL_PHASE_SLIP_REL * V0;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    test_rng rng = {97};
    int started = 0, moving = 0, slow = 0, from_rest = 0;
    double worst = -HUGE_VAL; /* the largest energy rise, per m g L */
    for (int k = 0; k < 2000; k++) {
        pd_state s;
        int contacts[8], nc = random_contact(b, &rng, &sc, &s, contacts);
        if (k % 2) { /* on an edge, where the projection takes an impulse */
            pd_state r = s;
            s = on_edge(b, rng_range(&rng, -0.3, 0.3), contacts, &nc);
            s.v = r.v, s.w = quat_rotate_inv(s.q, r.w);
            s.v.z -= contact_speed(b, &s, contacts[0]).z;
        }
        pd_vec3 u = contact_speed(b, &s, contacts[0]);
        double c = rng_range(&rng, 0.5, 4.0) * slip_min / hypot(u.x, u.y);
        s.v = v3_scale(s.v, c), s.w = v3_scale(s.w, c);
        pd_phase p;
        if (!pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &p))
            continue;
        started++;
        for (int i = 0; i < nc; i++) {
            pd_vec3 ui = contact_speed(b, &s, contacts[i]);
            if (p.mode[i] == PD_PHASE_STICK || p.from_rest[i])
                moving += v3_norm(ui) > 1e-12 * V0; /* round-off of the projection */
            else
                slow += !(hypot(ui.x, ui.y) > slip_min);
            from_rest += p.from_rest[i];
        }
        double E0 = total_energy(b, G, &s), t;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &p, &s, 0.5, &t) == PD_OK)
            worst = fmax(worst, (total_energy(b, G, &s) - E0) / mgL);
    }
    CHECK(started >= 300);
    CHECK_INT(moving, 0);
    CHECK_INT(slow, 0);
    /* Sticking phases of up to 1.7 sqrt(L/g) conserve energy to the ODE
     * error: measured 1.2e-8 m g L (2e-4 when the phase took its modes
     * afresh from the projected state). */
    CHECK_NEAR(fmax(worst, 0.0), 0.0, 10.0 * PD_TOL_PHASE_ODE_REL, "ODE error over a phase");
    pd_note("contact_phase: %d starts near the slip threshold (%d sliding from rest), energy rising "
            "at most %.1e m g L\n",
            started, from_rest, worst);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* The phase's integrator (rkck at PD_TOL_PHASE_ODE_REL) against rk8pd at
 * 1e-14 on random phases of the box, each run to a time limit short of any
 * event so that both end at the same time: the states agree to the error a
 * few steps of local error PD_TOL_PHASE_ODE_REL leave, and so does the
 * energy, which is what the energy test reads. The limit of 0.1 sqrt(L/g) is
 * 2-6 steps. Measured worst: 8e-10 L in position, 6e-9 sqrt(g L) in
 * velocity, 6e-8 in the rate of turn (the spin reaches 1.2 per sqrt(L/g)),
 * 1e-9 m g L in energy. */
static void test_reference_agreement(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    double t_max = 0.1 * sqrt(b->size / G);
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    pd_ode *ref = pd_ode_alloc_method(PD_ODE_RK8PD, 13, 1e-14, 1e-14);
    test_rng rng = {71};
    int compared = 0;
    state_gap gap = {0};
    for (int k = 0; k < 300; k++) {
        pd_state s;
        int contacts[8], nc = random_contact(b, &rng, &sc, &s, contacts);
        pd_phase phase;
        if (!pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &phase))
            continue;
        pd_state a = s, r = s;
        double ta, tr;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &phase, &a, t_max, &ta) != PD_OK ||
            pd_contact_phase(&fx.model->settle, ref, NULL, &sc, &phase, &r, t_max, &tr) != PD_OK ||
            ta < t_max * (1.0 - 1e-12) || tr < t_max * (1.0 - 1e-12))
            continue; /* an event or the energy test ended one of them */
        compared++;
        state_gap_add(&gap, b, G, &a, &r);
    }
    CHECK(compared >= 50);
    double tol = 10.0 * PD_TOL_PHASE_ODE_REL; /* a few steps of local error each */
    state_gap_check(&gap, tol);
    pd_note("contact_phase: rkck vs rk8pd on %d phases: x %.1e v %.1e q %.1e w %.1e E %.1e\n",
           compared, gap.x, gap.v, gap.q, gap.w, gap.E);
    pd_ode_free(ref);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* The specialised force solves (one sliding contact's 1 x 1 system, the
 * constant maps of sticking contacts, the body-axis rows of the rest)
 * against the general dense solve on the contacts' own tangent axes, on
 * random states of the box, every layout: equal to round-off. The least-norm
 * solve of two sticking contacts goes through the normal equations, which
 * square K's condition number (~1e3 for the box), so round-off ~1e-16 * 1e6:
 * 1e-9 of each quantity's scale. */
static void test_specialised_forces(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.5);
    if (!b)
        return;
    test_rng rng = {7};
    int layouts[2][3] = {{0}}, differ = 0;
    double worst = 0.0;
    for (int k = 0; k < 3000; k++) {
        double r[3][3];
        rng_rotation(&rng, r);
        pd_state s = {v3(0, 0, 0), quat_normalize(quat_from_matrix(CR(r))),
                      v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.0, 0.5)),
                      v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.0, 30.0))};
        int contacts[2] = {(int)(rng_uniform(&rng) * b->nverts), 0}, nc = 1 + (k % 2);
        int v = contacts[0], deg = b->adj_start[v + 1] - b->adj_start[v];
        contacts[1] = b->adj[b->adj_start[v] + (int)(rng_uniform(&rng) * deg)];
        /* Slip threshold: all slide, all stick, or between two slips. */
        double slip_start = (k / 2) % 3 == 0 ? 0.0 : (k / 2) % 3 == 1 ? HUGE_VAL : -1.0;
        if (slip_start < 0.0) {
            pd_phase p;
            pd_phase_init(&p, b, G, sc.mu, &s, contacts, nc, HUGE_VAL);
            pd_phase_forces F;
            pd_phase_forces_general(&p, &s, &F);
            slip_start = nc == 2 ? 0.5 * (F.slip[0] + F.slip[1]) : F.slip[0] * rng_range(&rng, 0.5, 1.5);
        }
        pd_phase p;
        pd_phase_init(&p, b, G, sc.mu, &s, contacts, nc, slip_start);
        pd_phase_forces A, B;
        int fa = pd_phase_forces_of(&p, &s, &A), fb = pd_phase_forces_general(&p, &s, &B);
        if (fa || fb) {
            differ += fa != fb;
            continue;
        }
        layouts[nc - 1][p.mode[0] + (nc == 2 ? p.mode[1] : 0)]++;
        double acc = G + v3_dot(s.w, s.w) * b->size, force = b->mass * acc;
        double d = fmax(v3_dist(A.acc, B.acc) / acc, v3_dist(A.wdot, B.wdot) * b->size / acc);
        for (int i = 0; i < nc; i++) {
            d = fmax(d, fabs(A.fn[i] - B.fn[i]) / force);
            d = fmax(d, fabs(A.slip[i] - B.slip[i]) / sqrt(acc * b->size));
            if (isfinite(B.cone[i]))
                d = fmax(d, fabs(A.cone[i] - B.cone[i]) / force);
            else
                differ += isfinite(A.cone[i]);
        }
        worst = fmax(worst, d);
    }
    CHECK_INT(differ, 0);
    CHECK_NEAR(worst, 0.0, 1e-9, "round-off through the normal equations (see above)");
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2 + i; j++)
            CHECK(layouts[i][j] >= 100);
    drop_teardown(&fx);
}

/* The phase's margins at s as the test reads them (contact_phase.c): normal
 * forces per weight, sticking cone margins per weight, slips above the end
 * threshold per sqrt(g L), the lowest other vertex above the contacts per L;
 * the smallest, or -1 where the model fails. */
static double least_margin(const pd_phase *p, const pd_state *s)
{
    const pd_body *b = p->b;
    pd_phase_forces F;
    if (pd_phase_forces_of(p, s, &F))
        return -1.0;
    double mg = b->mass * G, V0 = sqrt(G * b->size), least = HUGE_VAL, floor_z = HUGE_VAL;
    for (int i = 0; i < p->nc; i++) {
        least = fmin(least, F.fn[i] / mg);
        least = fmin(least, p->mode[i] == PD_PHASE_STICK
                                ? F.cone[i] / mg
                                : (F.slip[i] - PD_TOL_PHASE_SLIP_REL * V0) / V0);
        floor_z = fmin(floor_z, s->x.z + quat_rotate(s->q, b->verts[p->v[i]]).z);
    }
    for (int i = 0; i < b->nverts; i++)
        if (i != p->v[0] && i != p->v[1])
            least = fmin(least, (s->x.z + quat_rotate(s->q, b->verts[i]).z - floor_z) / b->size);
    return least;
}

/* One classical Runge-Kutta step of the phase's motion (SI). */
static void rk4_step(const pd_phase *p, pd_state *s, double dt)
{
    double y[13], k[4][13];
    const double c[4] = {0.0, 0.5, 0.5, 1.0}, wgt[4] = {1.0, 2.0, 2.0, 1.0};
    for (int stage = 0; stage < 4; stage++) {
        pd_state u = *s;
        if (stage > 0) {
            double *d = k[stage - 1], a = c[stage] * dt;
            u.x = v3_add(s->x, v3_scale(v3(d[0], d[1], d[2]), a));
            u.v = v3_add(s->v, v3_scale(v3(d[3], d[4], d[5]), a));
            u.q = quat_normalize(quat(s->q.w + a * d[6], s->q.x + a * d[7], s->q.y + a * d[8],
                                      s->q.z + a * d[9]));
            u.w = v3_add(s->w, v3_scale(v3(d[10], d[11], d[12]), a));
        }
        pd_phase_forces F;
        pd_phase_forces_of(p, &u, &F);
        pd_quat dq = quat_mul(u.q, quat(0.0, u.w.x, u.w.y, u.w.z));
        const double d[13] = {u.v.x, u.v.y, u.v.z, F.acc.x, F.acc.y, F.acc.z, 0.5 * dq.w,
                              0.5 * dq.x, 0.5 * dq.y, 0.5 * dq.z, F.wdot.x, F.wdot.y, F.wdot.z};
        memcpy(k[stage], d, sizeof d);
    }
    const double y0[13] = {s->x.x, s->x.y, s->x.z, s->v.x, s->v.y, s->v.z, s->q.w,
                           s->q.x, s->q.y, s->q.z, s->w.x, s->w.y, s->w.z};
    for (int i = 0; i < 13; i++) {
        y[i] = y0[i];
        for (int st = 0; st < 4; st++)
            y[i] += dt / 6.0 * wgt[st] * k[st][i];
    }
    *s = (pd_state){v3(y[0], y[1], y[2]), quat_normalize(quat(y[6], y[7], y[8], y[9])),
                    v3(y[3], y[4], y[5]), v3(y[10], y[11], y[12])};
}

/* Where a phase of random contacts of the box ends at an event (not the
 * energy test, not the time limit), it hands over with every margin still
 * positive and the event at most PD_TOL_PHASE_EVENT_REL sqrt(L/g) ahead:
 * continued by RK4 in steps of a fiftieth of that (error ~1e-30 L), some
 * margin reaches zero within it. */
static void test_event_location(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    double T = sqrt(b->size / G), tol = PD_TOL_PHASE_EVENT_REL * T;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    test_rng rng = {53};
    int events = 0, early = 0, late = 0, hint = 0, pose;
    double worst = 0.0;
    for (int k = 0; k < 300; k++) {
        pd_state s;
        int contacts[8], nc = random_contact(b, &rng, &sc, &s, contacts);
        pd_phase p;
        if (!pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &p))
            continue;
        double t;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &p, &s, 0.5, &t) != PD_OK || t >= 0.5 ||
            pd_settle_decided(&(fx.model)->settle, &s, G, &hint, &pose) > 0)
            continue;
        events++;
        if (!p.mapped)
            pd_phase_map(&p); /* a pivot's start leaves the solves out */
        early += !(least_margin(&p, &s) > 0.0);
        int steps = 0; /* of tol / 50 */
        while (steps < 100 && least_margin(&p, &s) > 0.0) {
            rk4_step(&p, &s, tol / 50.0);
            steps++;
        }
        late += steps > 50;
        worst = fmax(worst, steps / 50.0);
    }
    CHECK(events >= 100);
    CHECK_INT(early, 0);
    CHECK_INT(late, 0);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* A top: a flat square bipyramid (corners 1 cm out, apexes 0.1 mm up and
 * down) standing upright on its lower apex, spinning about the vertical at
 * w0. Drilling friction over the patch of radius a (settle.patch, from the
 * contact time) is a constant couple (2/3) mu m g a against the spin, so
 * the spin falls linearly and stops at t* = I w0 / ((2/3) mu m g a), I the
 * moment about the axis; the phase ends there (its spin margin), not
 * before, to within its event tolerance and the integration's error. The
 * top is flat so that, slowed below its gyroscopic limit, round-off tips it
 * by far less than lands a corner before t* (growth about 10 / s). */
static void test_drilling_top(void)
{
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    const double a = 0.01, c = 1e-4, w0 = 0.1;
    pd_vec3 p[6] = {{a, 0, 0}, {-a, 0, 0}, {0, a, 0}, {0, -a, 0}, {0, 0, c}, {0, 0, -c}};
    if (!drop_setup(&fx, convex_mesh(p, 6), &sc))
        return;
    const pd_body *b = fx.model->body;
    const pd_settle *st = &fx.model->settle;
    /* The axis: the largest moment's; the lower apex, the vertex furthest
     * along it. */
    int k = 0;
    for (int i = 1; i < 3; i++)
        if (b->moment[i] > b->moment[k])
            k = i;
    int apex = 0;
    double far = -1.0;
    for (int i = 0; i < b->nverts; i++) {
        pd_vec3 v = b->verts[i];
        double d = fabs(k == 0 ? v.x : k == 1 ? v.y : v.z);
        if (d > far)
            far = d, apex = i;
    }
    pd_state s = {v3(0, 0, 0), quat_onto_down(v3_unit(b->verts[apex])), v3(0, 0, 0), v3(0, 0, 0)};
    s.x.z = -quat_rotate(s.q, b->verts[apex]).z;
    s.w = quat_rotate_inv(s.q, v3(0, 0, w0));
    CHECK(st->patch > 0.0);
    pd_phase phase;
    int contacts[1] = {apex};
    CHECK(pd_contact_phase_start(st, &sc, &s, contacts, 1, &phase));
    CHECK(phase.drill[0] > 0.0);
    double t_star = b->moment[k] * w0 / (2.0 / 3.0 * sc.mu * b->mass * sc.gravity * st->patch);
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    double t = 0.0, T = sqrt(b->size / sc.gravity);
    CHECK_STATUS(pd_contact_phase(st, ode, pivot, &sc, &phase, &s, 4.0 * t_star, &t), PD_OK);
    /* Early by at most the event tolerance; the spin's decay is linear, which
     * the integrator follows to round-off. */
    CHECK(t <= t_star + 1e-9 * T);
    CHECK(t >= t_star - 2.0 * PD_TOL_PHASE_EVENT_REL * T);
    double wn = v3_dot(s.w, quat_rotate_inv(s.q, v3(0, 0, 1)));
    CHECK(wn >= 0.0 && wn <= w0 * 1e-5);
    pd_note("contact_phase: drilling top stops at %.9g s, predicted %.9g s (patch %.3g m)\n", t, t_star,
           st->patch);
    pd_ode_free(ode);
    pd_ode_free(pivot);
    drop_teardown(&fx);
}

/* A phase from resting state s on contacts[0..nc) at scene sc: admitted,
 * contact 0 moving along `out` (horizontal), friction taking energy (to the
 * phase's ODE error, 1e-8 m g L). */
static void slide_phase(const drop_fixture *fx, const pd_scene *sc, pd_state s, const int *contacts,
                        int nc, pd_vec3 out)
{
    const pd_body *b = fx->model->body;
    pd_vec3 c0 = v3_add(s.x, quat_rotate(s.q, b->verts[contacts[0]]));
    pd_phase phase;
    CHECK(pd_contact_phase_start(&fx->model->settle, sc, &s, contacts, nc, &phase));
    double E0 = total_energy(b, G, &s), dt = 0.0;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    CHECK_STATUS(pd_contact_phase(&fx->model->settle, ode, pivot, sc, &phase, &s, 1.0, &dt), PD_OK);
    CHECK(dt > 0.0);
    pd_vec3 c1 = v3_add(s.x, quat_rotate(s.q, b->verts[contacts[0]]));
    CHECK(v3_dot(v3_sub(c1, c0), out) > 0.0);
    CHECK(total_energy(b, G, &s) <= E0 + 1e-8 * b->mass * G * b->size);
    pd_ode_free(pivot);
    pd_ode_free(ode);
}

/* A 1 cm cube on one corner at rest, leaning (its centre of mass not above
 * the corner) with too little friction to hold the corner, starts to slide
 * from rest. Inertia isotropic (I = m a^2 / 6), so in the vertical plane of
 * the corner's arm r from the centre (rho horizontal, -h vertical) the
 * corner slides outward, along r's horizontal part, under the normal force
 * lambda = g / (1/m + rho (rho - mu h) / I) and with acceleration
 * lambda (h rho - mu (I/m + h^2)) / I, positive below mu* = h rho /
 * (I/m + h^2). Above mu* the corner sticks: no slide. Microcollisions used
 * to stop such a corner's slip at every rest step; the phase now takes it
 * (pd_contact_phase_start refused it, its sticking force outside the cone),
 * friction only taking energy. */
static void test_slide_from_rest(void)
{
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    if (!drop_setup(&fx, mesh_box(0.01, 0.01, 0.01), &sc))
        return;
    const pd_body *b = fx.model->body;
    pd_quat q = quat_mul(quat_axis_angle(v3(1, 0, 0), 0.3), quat_onto_down(v3_unit(v3(1, 1, 1))));
    int contacts[8], nc = lowest_vertices(b, q, contacts);
    CHECK_INT(nc, 1);
    pd_vec3 r = quat_rotate(q, b->verts[contacts[0]]);
    pd_state s = {v3(0, 0, -r.z), q, v3(0, 0, 0), v3(0, 0, 0)};
    double rho = hypot(r.x, r.y), h = -r.z, Im = b->moment[0] / b->mass;
    double mu_star = h * rho / (Im + h * h), L = b->size;
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(G * L);
    for (int k = 0; k < 2; k++) {
        double mu = (k ? 1.1 : 0.5) * mu_star, accel = 0.0;
        pd_phase p;
        pd_phase_init(&p, b, G, mu, &s, contacts, nc, slip_start);
        CHECK_INT(p.mode[0], PD_PHASE_STICK);
        int slides = pd_phase_slide_from_rest(&p, &s, &accel);
        CHECK_INT(slides, !k);
        if (!slides)
            continue;
        double lambda = G / (1.0 / b->mass + rho * (rho - mu * h) / b->moment[0]);
        double a = lambda * (h * rho - mu * (Im + h * h)) / b->moment[0];
        CHECK_REL(accel, a, 1e-12, "closed form; round-off of the narrowed zero");
        CHECK_NEAR(p.t0[0].x - r.x / rho, 0.0, 1e-12, "outward along the arm, by symmetry");
        CHECK_NEAR(p.t0[0].y - r.y / rho, 0.0, 1e-12, "outward along the arm, by symmetry");
    }
    /* The phase: admitted, and the corner slides outward, friction taking
     * energy (to the phase's ODE error). */
    sc.mu = 0.5 * mu_star;
    slide_phase(&fx, &sc, s, contacts, nc, v3(r.x, r.y, 0.0));
    drop_teardown(&fx);
}

/* The 1 x 2 x 3 cm box on its long edge, at rest, leaning tilt past
 * balance with too little friction to hold the edge: both of the edge's
 * contacts slide from rest, outward and together (the motion is planar),
 * under the closed form of test_slide_from_rest with I the moment about the
 * edge's direction and (rho, h) the arm from the edge to the centre. */
static void test_edge_slide_from_rest(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    int contacts[8], nc;
    pd_state s = on_edge(b, 0.2, contacts, &nc);
    CHECK_INT(nc, 2);
    /* The edge lies along the world's x (on_edge turns about it): the arm
     * across it is (y, z). */
    pd_vec3 r = quat_rotate(s.q, b->verts[contacts[0]]);
    double rho = fabs(r.y), h = -r.z, Im = b->moment[0] / b->mass, L = b->size;
    double mu_star = h * rho / (Im + h * h), out = r.y > 0.0 ? 1.0 : -1.0;
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(G * L);
    for (int k = 0; k < 2; k++) {
        double mu = (k ? 1.1 : 0.5) * mu_star, accel = 0.0;
        pd_phase p;
        pd_phase_init(&p, b, G, mu, &s, contacts, nc, slip_start);
        CHECK(p.mode[0] == PD_PHASE_STICK && p.mode[1] == PD_PHASE_STICK);
        int slides = pd_phase_slide_edge_from_rest(&p, &s, &accel);
        CHECK_INT(slides, !k);
        if (!slides)
            continue;
        double lambda = G / (1.0 / b->mass + rho * (rho - mu * h) / b->moment[0]);
        double a = lambda * (h * rho - mu * (Im + h * h)) / b->moment[0];
        CHECK_REL(accel, a, 1e-9, "closed form; Newton's stop at 1e-12 g of the residual");
        for (int i = 0; i < 2; i++) {
            CHECK_NEAR(p.t0[i].x, 0.0, 1e-9, "outward across the edge, by symmetry");
            CHECK_NEAR(p.t0[i].y, out, 1e-9, "outward across the edge, by symmetry");
        }
    }
    sc.mu = 0.5 * mu_star;
    slide_phase(&fx, &sc, s, contacts, nc, v3(0.0, out, 0.0));
    drop_teardown(&fx);
}

/* The 1 x 2 x 3 cm box on its long edge, leaning nearly onto a side face
 * (1e-5 rad above the floor) and turning onto it: its edge cannot stick,
 * and the face's far vertex lands before the slips reach a slide's speed
 * (checked here to first order, as lands_first judges a lone contact).
 * The edge's slide from rest is a phase all the same (it was refused, and
 * microcollisions stopped the slip a rest step at a time until the
 * landing); the phase slides the edge outward, ends before that vertex is
 * below the floor by more than the event tolerance's travel, and friction
 * only takes energy (to the phase's ODE error). */
static void test_edge_slide_into_landing(void)
{
    pd_scene sc;
    drop_fixture fx;
    pd_state s;
    int contacts[8], nc = 2;
    const pd_body *b = box_on_edge(&fx, &sc, 0.3, 0.0, 1e-5, &s, contacts);
    if (!b)
        return;
    const double rate = 0.05 / sqrt(b->size / G);
    /* The pivot's rate about the edge (body x), turning onto the face. */
    pd_vec3 r0 = quat_rotate(s.q, b->verts[contacts[0]]);
    s.w = v3(rate, 0.0, 0.0);
    s.v = v3_neg(v3_cross(quat_rotate(s.q, s.w), r0));
    /* The landing vertex: the lowest other one, and its first-order height
     * at the slide's horizon. */
    double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(G * b->size), accel = 0.0;
    pd_phase p;
    pd_phase_init(&p, b, G, sc.mu, &s, contacts, nc, slip_start);
    CHECK(pd_phase_slide_edge_from_rest(&p, &s, &accel));
    int w = -1;
    double hw = HUGE_VAL;
    for (int i = 0; i < b->nverts; i++) {
        double z = pd_body_vertex_world(b, &s, i).z;
        if (i != contacts[0] && i != contacts[1] && z < hw)
            hw = z, w = i;
    }
    pd_vec3 rw = quat_rotate(s.q, b->verts[w]);
    double vz = s.v.z + v3_cross(quat_rotate(s.q, s.w), rw).z;
    CHECK(hw + vz * slip_start / accel <= 0.0); /* lands first */
    pd_phase phase;
    pd_state t = s;
    if (!edge_slide_starts(&fx, &sc, &t, contacts, &phase, 1)) {
        drop_teardown(&fx);
        return;
    }
    double E0 = total_energy(b, G, &t), dt = 0.0;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    CHECK_STATUS(pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &phase, &t, 1.0, &dt), PD_OK);
    CHECK(dt > 0.0);
    CHECK(pd_body_vertex_world(b, &t, w).z >= -PD_TOL_PHASE_EVENT_REL * sqrt(b->size / G) * fabs(vz));
    CHECK(total_energy(b, G, &t) <= E0 + 1e-8 * b->mass * G * b->size);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* The 1 x 2 x 3 cm box on its long edge, leaning past balance, turning
 * about the vertical through one end of the edge: that end at rest, the
 * other sliding. With friction 0.05 the resting end's sticking force lies
 * outside the cone, and it slides from rest too (it was refused, and
 * microcollisions stopped its slip a rest step at a time): the start is
 * admitted with both ends sliding, the resting one from rest along a
 * direction in which its tangential acceleration under the phase's own
 * force solve lies (to 1e-9 g: the narrowing's round-off with the solves'),
 * outward, under positive normal forces; and the phase's energy only
 * falls (to its ODE error). */
static void test_edge_end_slides_from_rest(void)
{
    pd_scene sc;
    drop_fixture fx;
    pd_state s;
    int contacts[8];
    const pd_body *b = box_on_edge(&fx, &sc, 0.05, 0.2, 0.0, &s, contacts);
    if (!b)
        return;
    pd_vec3 r0 = quat_rotate(s.q, b->verts[contacts[0]]), om = v3(0.0, 0.0, 2.0);
    s.w = quat_rotate_inv(s.q, om);
    s.v = v3_neg(v3_cross(om, r0));
    pd_phase phase;
    if (!edge_slide_starts(&fx, &sc, &s, contacts, &phase, 0)) {
        drop_teardown(&fx);
        return;
    }
    pd_phase_forces F;
    CHECK(!pd_phase_forces_of(&phase, &s, &F));
    pd_vec3 w = quat_rotate(s.q, s.w), alpha = quat_rotate(s.q, F.wdot);
    pd_vec3 r = quat_rotate(s.q, b->verts[phase.v[0]]), t = phase.t0[0];
    pd_vec3 a = v3_add(F.acc, v3_add(v3_cross(alpha, r), v3_cross(w, v3_cross(w, r))));
    CHECK_NEAR(t.x * a.y - t.y * a.x, 0.0, 1e-9 * G, "slip grows along its direction");
    CHECK(t.x * a.x + t.y * a.y > 0.0);
    CHECK(F.fn[0] > 0.0 && F.fn[1] > 0.0);
    double E0 = total_energy(b, G, &s), dt = 0.0;
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    CHECK_STATUS(pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &phase, &s, 1.0, &dt), PD_OK);
    CHECK(dt > 0.0);
    CHECK(total_energy(b, G, &s) <= E0 + 1e-8 * b->mass * G * b->size);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* A tetrahedron of vertices v[4] (A = v[0], B = v[1] on the plane z = 0),
 * set up for scene sc, at rest in its own frame as the world's, A and B on
 * the floor: its body, or NULL; its lowest vertices into contacts, *nc. */
static const pd_body *tetra_on_edge(drop_fixture *fx, const pd_scene *sc, const pd_vec3 v[4],
                                    pd_state *s, int *contacts, int *nc)
{
    if (!drop_setup(fx, convex_mesh(v, 4), sc))
        return NULL;
    const pd_body *b = fx->model->body;
    *s = (pd_state){v3_add(fx->part->origin, b->com), b->frame, v3(0, 0, 0), v3(0, 0, 0)};
    *nc = lowest_vertices(b, s->q, contacts);
    return b;
}

/* A tetrahedron resting on its edge AB at rest, its centre of mass off
 * the edge's middle and leaning past it, with too little friction to hold
 * the edge: the weight's moment yaws it as it topples, so its two contacts'
 * slides from rest part. Where a pair is found, each contact's tangential
 * acceleration under the phase's own force solve (pd_phase_forces_of, not
 * the search's residual) lies along its direction, outward, under a
 * positive normal force. Tolerance: Newton's stop at 1e-12 g of the
 * residual, with the solves' round-off. */
static void test_edge_slide_apart(void)
{
    const double mus[3] = {0.02, 0.05, 0.1};
    int found = 0;
    for (int k = 0; k < 3; k++) {
        pd_scene sc;
        pd_scene_default(&sc);
        sc.mu = mus[k];
        drop_fixture fx;
        const pd_vec3 v[4] = {{0, 0, 0}, {0.01, 0, 0}, {0.002, 0.008, 0.008}, {0.003, -0.002, 0.009}};
        pd_state s;
        int contacts[8], nc;
        const pd_body *b = tetra_on_edge(&fx, &sc, v, &s, contacts, &nc);
        if (!b)
            return;
        CHECK_INT(nc, 2);
        double slip_start = 2.0 * PD_TOL_PHASE_SLIP_REL * sqrt(G * b->size), accel = 0.0;
        pd_phase p;
        if (nc == 2) {
            pd_phase_init(&p, b, G, sc.mu, &s, contacts, nc, slip_start);
            CHECK(p.mode[0] == PD_PHASE_STICK && p.mode[1] == PD_PHASE_STICK);
        }
        if (nc == 2 && pd_phase_slide_edge_from_rest(&p, &s, &accel)) {
            found++;
            pd_phase_forces F;
            CHECK(!pd_phase_forces_of(&p, &s, &F));
            pd_vec3 alpha = quat_rotate(s.q, F.wdot);
            for (int i = 0; i < 2; i++) {
                pd_vec3 r = quat_rotate(s.q, b->verts[contacts[i]]), t = p.t0[i];
                pd_vec3 a = v3_add(F.acc, v3_cross(alpha, r));
                CHECK_NEAR(t.x * a.y - t.y * a.x, 0.0, 1e-9 * G, "slip grows along its direction");
                CHECK(t.x * a.x + t.y * a.y > 0.0);
                CHECK(F.fn[i] > 0.0);
            }
            /* the two directions differ: not a planar slide */
            CHECK(fabs(p.t0[0].x * p.t0[1].y - p.t0[0].y * p.t0[1].x) > 1e-3);
        }
        drop_teardown(&fx);
    }
    CHECK(found > 0);
}

/* A tetrahedron resting on its edge AB, its centre of mass beyond A: the
 * weight's moment about A lifts B, whose normal force would be negative in
 * an edge phase. B lifts off, and the phase is A's alone (the edge's start
 * was refused, and microcollisions took it a rest step at a time). */
static void test_edge_lifts_one_end(void)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.mu = 1.0; /* A sticks */
    drop_fixture fx;
    const pd_vec3 p[4] = {{0, 0, 0}, {0.01, 0, 0}, {-0.015, 0.005, 0.01}, {-0.015, -0.005, 0.01}};
    pd_state s;
    int contacts[8], nc;
    const pd_body *b = tetra_on_edge(&fx, &sc, p, &s, contacts, &nc);
    if (!b)
        return;
    CHECK_INT(nc, 2);
    if (nc != 2)
        return;
    int a = pd_body_vertex_world(b, &s, contacts[0]).x < pd_body_vertex_world(b, &s, contacts[1]).x ? 0 : 1;
    CHECK_NEAR(pd_body_vertex_world(b, &s, contacts[a]).z, 0.0, 1e-15, "A on the floor");
    pd_phase phase;
    CHECK(pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, nc, &phase));
    CHECK_INT(phase.nc, 1);
    CHECK_INT(phase.v[0], contacts[a]);
    CHECK_INT(phase.mode[0], PD_PHASE_STICK);
    drop_teardown(&fx);
}

/* A clipped contact (PD_PHASE_CLIP, the slip onset where the slide from rest
 * finds no direction or cannot be judged): the box at rest on a corner,
 * friction 0.1, its sticking force outside the cone, clipped: its friction
 * mu fn exactly, the contact held on the floor (no normal acceleration), the
 * sticking force's excess over the cone reported as its margin, the energy
 * never rising beyond the integration error over its phase, and the phase
 * ending before the slip passes the speed at which a slide starts (twice
 * the end threshold). */
static void test_clipped_slip(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.1);
    if (!b)
        return;
    /* Per part units: sqrt(g L) and m g L. */
    double V0 = sqrt(G * b->size), mgL = b->mass * G * b->size;
    test_rng rng = {53};
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    int clipped = 0, rises = 0, off_cone = 0, lifts = 0, fast = 0;
    for (int k = 0; k < 300; k++) {
        double r[3][3];
        rng_rotation(&rng, r);
        pd_state s = {v3(0, 0, 0), quat_normalize(quat_from_matrix(CR(r))), v3(0, 0, 0),
                      v3(0, 0, 0)};
        int contacts[8], nc = lowest_vertices(b, s.q, contacts);
        if (nc != 1)
            continue;
        s.x.z = -quat_rotate(s.q, b->verts[contacts[0]]).z;
        pd_phase p;
        pd_phase_forces F;
        pd_phase_init(&p, b, G, sc.mu, &s, contacts, 1, 2.0 * PD_TOL_PHASE_SLIP_REL * V0);
        if (pd_phase_forces_of(&p, &s, &F) || !(F.cone[0] < 0.0))
            continue;
        double outside = -F.cone[0];
        p.mode[0] = PD_PHASE_CLIP;
        clipped++;
        if (pd_phase_forces_of(&p, &s, &F)) {
            CHECK(0);
            continue;
        }
        off_cone += fabs(F.cone[0] - outside) > 1e-12 * b->mass * G;
        /* Its force on the cone's edge: the centre's horizontal
         * acceleration is the friction's, mu fn / m. */
        off_cone += fabs(hypot(F.acc.x, F.acc.y) - sc.mu * F.fn[0] / b->mass) >
                    1e-12 * G * (1.0 + sc.mu);
        /* The contact's normal acceleration: the centre's, plus the turn's
         * (at rest, wdot x r alone). */
        pd_vec3 rw = quat_rotate(s.q, b->verts[contacts[0]]);
        lifts += fabs(F.acc.z + v3_cross(quat_rotate(s.q, F.wdot), rw).z) > 1e-12 * G;
        double E0 = total_energy(b, G, &s), t;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &p, &s, 0.5, &t) != PD_OK)
            continue;
        rises += total_energy(b, G, &s) > E0 + 1e-8 * mgL;
        pd_vec3 u = contact_speed(b, &s, contacts[0]);
        fast += hypot(u.x, u.y) > 2.0 * PD_TOL_PHASE_SLIP_REL * V0 * (1.0 + 1e-6);
    }
    CHECK(clipped >= 50);
    CHECK_INT(off_cone, 0);
    CHECK_INT(lifts, 0);
    CHECK_INT(rises, 0);
    CHECK_INT(fast, 0);
    pd_note("contact_phase: %d of 300 corners at rest clipped\n", clipped);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

/* A lone vertex that sticks until its force reaches the cone goes on
 * sliding from rest within the same phase, so no sticking phase ends at its cone
 * (where one did, the next started just short of the crossing again: a
 * contact grazing the cone took one phase and one microcollision per
 * step). The box on a corner, slowly turning, friction 0.5 to 3: phases
 * that start sticking; none ends with the contact still at rest and its
 * sticking force on the cone. */
static void test_slip_onset_in_phase(void)
{
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.5);
    if (!b)
        return;
    double V0 = sqrt(G * b->size), mg = b->mass * G;
    test_rng rng = {71};
    pd_ode *ode = pd_contact_phase_ode_alloc(), *pivot = pd_contact_pivot_ode_alloc();
    int sticking = 0, at_cone = 0;
    for (int k = 0; k < 400; k++) {
        double r[3][3];
        rng_rotation(&rng, r);
        sc.mu = rng_range(&rng, 0.5, 3.0);
        pd_state s = {v3(0, 0, 0), quat_normalize(quat_from_matrix(CR(r))), v3(0, 0, 0),
                      v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.0, 2.0))};
        int contacts[8], nc = lowest_vertices(b, s.q, contacts);
        if (nc != 1)
            continue;
        s.x.z = -quat_rotate(s.q, b->verts[contacts[0]]).z;
        s.v = v3_neg(quat_rotate(s.q, v3_cross(s.w, b->verts[contacts[0]]))); /* at rest */
        pd_phase p;
        double t;
        if (!pd_contact_phase_start(&fx.model->settle, &sc, &s, contacts, 1, &p) ||
            p.mode[0] != PD_PHASE_STICK)
            continue;
        sticking++;
        if (pd_contact_phase(&fx.model->settle, ode, pivot, &sc, &p, &s, 0.5, &t) != PD_OK)
            continue;
        pd_phase_forces F;
        pd_vec3 u = contact_speed(b, &s, contacts[0]);
        /* Ended on the cone, sticking: its margin within 1e-4 of the
         * weight (the event tolerance times its rate: measured 7e-7 to 2e-6
         * where the phases ended there, 28 of 381 before the switch), the
         * slip within 1e-7 sqrt(g L) (the integration error: 1e-9). */
        at_cone += !pd_phase_forces_of(&p, &s, &F) && F.fn[0] > 1e-3 * mg &&
                   fabs(F.cone[0]) < 1e-4 * mg && hypot(u.x, u.y) < 1e-7 * V0;
    }
    CHECK(sticking >= 50);
    CHECK_INT(at_cone, 0);
    pd_note("contact_phase: %d sticking corners, %d ended on the cone\n", sticking, at_cone);
    pd_ode_free(pivot);
    pd_ode_free(ode);
    drop_teardown(&fx);
}

void suite_contact_phase(void)
{
    test_clipped_slip();
    test_slip_onset_in_phase();
    test_drilling_top();
    test_event_location();
    test_specialised_forces();
    test_edge_slide();
    test_edge_topple();
    test_random_phases();
    test_reference_agreement();
    test_start_modes();
    test_slide_from_rest();
    test_edge_slide_from_rest();
    test_edge_slide_apart();
    test_edge_slide_into_landing();
    test_edge_end_slides_from_rest();
    test_edge_lifts_one_end();
}
