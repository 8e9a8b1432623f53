/* engine_ode.c: the Open Dynamics Engine backend (see engine.h). The only file
 * that includes ODE's headers.
 *
 * The ODE body's frame is the principal frame of pd_body: origin at the centre
 * of mass, axes along the principal axes. So its mass is diagonal, a
 * pd_state's position and orientation are the body's own, and the hull's
 * vertices are already in that frame. The floor's contacts are found here
 * (floor_contacts), not by ODE's collision functions.
 *
 * Solver: dWorldStep, ODE's direct (Dantzig LCP) solver, not dWorldQuickStep.
 * One body with at most PD_ODE_MAX_CONTACTS contacts makes at most 24
 * constraint rows, which the direct solver solves exactly in microseconds;
 * QuickStep's fixed number of SOR sweeps leaves a residual that shows as
 * creep and jitter of a resting part, which would blur the very rest test the
 * drops end on.
 *
 * Friction: ODE has no exact Coulomb cone; dContactApprox1 gives a pyramid
 * whose limits are mu times the normal force of the same step (without it
 * ODE reads mu as a force in newtons). The pyramid's first axis is turned
 * along the sliding velocity. A contact that slides (PD_ENGINE_SLIDE_STEPS)
 * has friction along that axis alone, so it meets exactly mu N against its
 * motion and none across it; with the second axis too, that axis's row
 * held the slip's direction fixed with up to mu N more across it (a sliding
 * impact's friction up to sqrt(2) mu N, and the slip never turned). A
 * contact that sticks or slips slower gets both axes, so that a resting
 * part does not creep; only a stick broken diagonally sees the pyramid's up
 * to sqrt(2) larger corner.
 *
 * Units: ODE is handed the part in units near its own size L, mass m and
 * time sqrt(L/g) (powers of two, so the conversions are exact), and every
 * quantity it sees is of order 1 whatever the part. ODE's dense LCP solver
 * is not scale-free: it removes a row from its factorisation by adding 1 to
 * a diagonal of J M^-1 J^T, whose entries are ~1/m in kg^-1; in SI units
 * that sum loses every digit for a small part and the factorisation breaks
 * down ("d[i] != 0" in dxLDLTRemove): every cube of side 2 mm or less tried
 * (mass = volume, 1/m >= 1.25e8 kg^-1) aborted within 300 drops, 3 mm and
 * up never. In these units the physics is the same (every law here is
 * homogeneous in L, m and time) and the matrix is ~1.
 *
 * Failures: ODE reports an internal error through its error and debug
 * handlers and aborts the process if they return. Every call into ODE runs
 * under a jump buffer of its thread (ode_guard), and the handlers jump back
 * to it: the call fails with PD_ERR_NO_CONVERGENCE, the world's ODE objects,
 * in whatever state the error left them, are set aside and built again, and
 * the drop ends as failed (counted with the unsettled) while the process and
 * the other threads' worlds go on. */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <ode/ode.h>
#include "engines/engine.h"
#include "engines/engine_contact.h"
#include "base/base_tol.h"
#include "engines/engines_tol.h"
#include "base/vec3.h"
#include "posedrop/tolerances.h"

/* Under the address sanitizer's leak checker: see step_memory_untracked. */
#if defined(__SANITIZE_ADDRESS__)
#define ODE_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define ODE_LSAN 1
#endif
#endif
#ifdef ODE_LSAN
#include <sanitizer/lsan_interface.h>
#endif

/* libode-dev is built in double precision (dGetConfiguration reports
 * ODE_double_precision); the states cross over as doubles (scaled by powers
 * of two, exactly) and the tests' round-off bounds assume it. A
 * single-precision ODE would need its own tolerances, so it is refused at
 * compile time. */
_Static_assert(sizeof(dReal) == sizeof(double), "ODE must be built with dDOUBLE");

struct pd_engine_world {
    dWorldID world;
    dBodyID body;
    dJointGroupID contacts;
    dThreadingImplementationID threading;
    /* The hull's vertices, body frame, and room for a contact at each. */
    pd_vec3 *points;
    int npoints;
    dContactGeom *cand;
    double *mind;
    /* Per hull vertex: the approach speed of its impact under way (at least
     * v_rest; negative once it recedes), 0 while it is above the floor; the
     * contact law's damping is chi over it (pd_engine_hc_law,
     * touch_speeds). */
    double *touch;
    /* What a rebuild needs, in ODE's units (see the top): mass and
     * principal moments, gravity along -z. */
    double mass, moment[3], gravity;
    /* The units: length, time, and velocity = length / time. */
    double len, time, vel;
    double dt; /* in time units */
    double mu, restitution, bounce_vel;
    /* A contact slipping faster than this slides through the step:
     * PD_ENGINE_SLIDE_STEPS steps of friction under the part's weight. */
    double slide_speed;
    double erp, cfm;
    /* contact_time > 0 and resolved by the step: each contact is the
     * scene's law (pd_engine_hc_law) for its effective mass, in ODE's units;
     * v_rest, the speed of resting contact's fall (the impulse simulator's,
     * settle.c), bounds the approach speed the damping is divided by. */
    int compliant;
    double omega, chi, v_rest;
    /* The linear spring-dashpot's omega for T and e (pd_engine_contact_law),
     * which sets the drilling patch (drilling_arm). */
    double patch_omega;
    /* The part's thickness and size, m, for pd_engine_contact_resolved. */
    double width_m, size_m;
    /* ODE's units: gravity's magnitude for the scales, the part's size;
     * and the drilling couple's arm, (2/3) mu a (drilling_arm). */
    double gscale, size, drill;
    int lost; /* its ODE objects failed and could not be quarantined */
};

/* The jump buffer of the ODE call under way in this thread, if any. ODE's
 * handlers are process-wide; each thread jumps back into its own call. */
static _Thread_local jmp_buf *ode_jump;

/* ODE's global initialisation, once per process. dCloseODE runs at exit (an
 * atexit handler registered by the same once-routine), never earlier: worlds
 * in other threads may exist at any time before that, and ODE must not be
 * closed under them. Its non-fatal messages (e.g. an LCP that could not be
 * solved exactly) are silenced: the library does not print, and step reports
 * failure through the state it reads back. */
static pthread_once_t ode_once = PTHREAD_ONCE_INIT;
static int ode_ready;

static void ode_silent(int errnum, const char *msg, va_list ap)
{
    (void)errnum;
    (void)msg;
    (void)ap;
}

/* An internal error or a failed assertion in ODE: back to the guarded call
 * of this thread. Every call into ODE is guarded (ode_guard), so a handler
 * that found none would be a bug of this file; ODE then aborts, as it
 * would have without the handler. */
static void ode_fatal(int errnum, const char *msg, va_list ap)
{
    (void)errnum;
    (void)msg;
    (void)ap;
    if (ode_jump)
        longjmp(*ode_jump, 1);
}

static void ode_close(void) { dCloseODE(); }

static void ode_init(void)
{
    if (!dInitODE2(0))
        return;
    dSetMessageHandler(ode_silent);
    dSetErrorHandler(ode_fatal);
    dSetDebugHandler(ode_fatal);
    /* If atexit cannot register, ODE is simply never closed: the process
     * exit reclaims it, and it stays usable until then. */
    (void)atexit(ode_close);
    ode_ready = 1;
}

/* The hull's vertices in the principal frame (pd_body's), in ODE's units,
 * and the contact buffers. */
static int build_points(pd_engine_world *w, const pd_body *body)
{
    size_t nv = (size_t)body->nverts;
    w->points = malloc(sizeof *w->points * nv);
    w->cand = malloc(sizeof *w->cand * nv);
    w->mind = malloc(sizeof *w->mind * nv);
    w->touch = calloc(nv, sizeof *w->touch);
    if (!w->points || !w->cand || !w->mind || !w->touch)
        return 0;
    for (size_t i = 0; i < nv; i++)
        w->points[i] = v3_scale(body->verts[i], 1.0 / w->len);
    w->npoints = body->nverts;
    return 1;
}

/* With zero gravity there is no weight or fall speed to scale the contact
 * by; standard gravity's stands in. */
static double scale_gravity(const pd_scene *scene)
{
    double g = fabs(scene->gravity);
    return g > 0.0 ? g : 9.81;
}

/* Contact softness, in ODE's units: one contact carrying the weight m g
 * sinks PD_ODE_SINK_REL * L, so kp = m g / (PD_ODE_SINK_REL L), damped at
 * PD_ODE_DAMPING_RATIO of critical, kd = 2 zeta sqrt(kp m). ODE's spring
 * form for a step h: erp = h kp / (h kp + kd), cfm = 1 / (h kp + kd). */
static void contact_softness(pd_engine_world *w, double g, double size)
{
    double kp = w->mass * g / (PD_ODE_SINK_REL * size);
    double kd = 2.0 * PD_ODE_DAMPING_RATIO * sqrt(kp * w->mass);
    double h = w->dt;
    w->erp = h * kp / (h * kp + kd);
    w->cfm = 1.0 / (h * kp + kd);
}

/* The world's ODE objects, from the numbers in w; 0 on
 * failure (what was made is left for ode_objects_free). Runs guarded. */
static int ode_objects_build(pd_engine_world *w)
{
    w->world = dWorldCreate();
    w->contacts = w->world ? dJointGroupCreate(0) : NULL;
    /* Without one of its own, a world steps on ODE's process-wide default
     * threading object, whose fake locks assert when two threads step at
     * once (measured: "assertion failed in WaitWakeup"). One self-threaded
     * implementation per world keeps the worlds independent. */
    w->threading = w->contacts ? dThreadingAllocateSelfThreadedImplementation() : NULL;
    if (!w->threading)
        return 0;
    dWorldSetStepThreadingImplementation(w->world, dThreadingImplementationGetFunctions(w->threading),
                                         w->threading);
    dWorldSetGravity(w->world, 0.0, 0.0, -w->gravity);
    /* The contacts' normal rows carry their own erp and cfm; every other
     * row (friction, drilling) takes the world's cfm, which makes friction
     * a damper of coefficient 1/cfm: see PD_ODE_FRICTION_CFM. */
    dWorldSetERP(w->world, w->erp);
    dWorldSetCFM(w->world, PD_ODE_FRICTION_CFM);
    /* A surface layer would let the part rest that far inside the floor;
     * heights must be the facet's. */
    dWorldSetContactSurfaceLayer(w->world, 0.0);

    w->body = dBodyCreate(w->world);
    if (!w->body)
        return 0;
    dMass m;
    dMassSetParameters(&m, w->mass, 0.0, 0.0, 0.0, w->moment[0], w->moment[1], w->moment[2], 0.0,
                       0.0, 0.0);
    dBodySetMass(w->body, &m);
    /* The exact rotation for the step's angular velocity instead of the
     * first-order quaternion update: a tumbling part keeps its unit norm
     * without renormalisation drift, and free flight is closer to Euler's
     * equations. */
    dBodySetFiniteRotationMode(w->body, 1);
    dBodySetAutoDisableFlag(w->body, 0);
    return 1;
}

/* A step that an internal error interrupts leaves a job record of the
 * world's threading object referenced from the abandoned stack only: lost
 * memory, 80 bytes per failure, that no code can reach or free. The leak
 * checker (sanitizer builds only) is told not to track what ODE allocates
 * inside a step, so that the deliberate loss does not fail the build; the
 * objects that are kept (the quarantine below) stay checked as reachable. */
static _Thread_local int step_untracked;

static void step_memory_untracked(int on)
{
#ifdef ODE_LSAN
    if (on && !step_untracked)
        __lsan_disable();
    else if (!on && step_untracked)
        __lsan_enable();
#endif
    step_untracked = on;
}

/* ODE objects that an internal error interrupted cannot be destroyed: their
 * destructors assert on the step left half done (a job still queued on the
 * world's threading object), and that assertion would end in the same
 * error. They are kept here, reachable, for the life of the process, and a
 * world that failed is built anew. At most ODE_QUARANTINE of them: a world
 * that fails when the quarantine is full is not rebuilt (its drops fail from
 * then on), which bounds the memory a run can lose this way. */
enum { ODE_QUARANTINE = 256 };

typedef struct {
    dWorldID world;
    dJointGroupID contacts;
    dThreadingImplementationID threading;
} ode_objects;

static pthread_mutex_t quarantine_lock = PTHREAD_MUTEX_INITIALIZER;
/* volatile: nothing reads the array, and the compiler may drop stores that
 * nothing reads; the pointers must be in memory to keep the objects
 * reachable (a leak checker looks for them there). */
static volatile ode_objects quarantine[ODE_QUARANTINE];
static int quarantined;

/* Moves w's ODE objects to the quarantine; 0 if it is full then, and they
 * stay with w, never to be touched again (w->lost). */
static int quarantine_objects(pd_engine_world *w)
{
    ode_objects o = {w->world, w->contacts, w->threading};
    int room = 0;
    if (pthread_mutex_lock(&quarantine_lock) == 0) {
        room = quarantined < ODE_QUARANTINE;
        if (room) {
            quarantine[quarantined].world = o.world;
            quarantine[quarantined].contacts = o.contacts;
            quarantine[quarantined].threading = o.threading;
            quarantined++;
        }
        (void)pthread_mutex_unlock(&quarantine_lock);
    }
    w->body = NULL;
    if (!room) {
        w->lost = 1;
        return 0;
    }
    w->world = NULL;
    w->contacts = NULL;
    w->threading = NULL;
    return 1;
}

/* The operations run under ode_guard. */
typedef enum { ODE_BUILD, ODE_RESET, ODE_STEP, ODE_FREE } ode_op;

static int ode_reset_body(pd_engine_world *w, const pd_state *s);
static pd_status ode_step_body(pd_engine_world *w, pd_state *s);

/* Destroys the world's ODE objects (not the vertex arrays); each pointer is
 * cleared as its object goes, so that after an error part way only what is
 * left is quarantined. */
static void ode_objects_free(pd_engine_world *w)
{
    if (w->contacts)
        dJointGroupDestroy(w->contacts);
    w->contacts = NULL;
    if (w->world)
        dWorldDestroy(w->world); /* also destroys the body */
    w->world = NULL;
    w->body = NULL;
    if (w->threading)
        dThreadingFreeImplementation(w->threading);
    w->threading = NULL;
}

/* Runs op on w with this thread's jump buffer set, so that an ODE internal
 * error comes back here instead of aborting: the call fails with
 * PD_ERR_NO_CONVERGENCE, w's ODE objects go to the quarantine, and (after a
 * reset or a step) new ones are built, under a guard of their own. If that
 * build fails too, w keeps no ODE objects and every later call fails
 * cleanly. What is read after the jump is volatile or set before setjmp. */
static pd_status ode_guard(pd_engine_world *w, ode_op op, pd_state *s)
{
    jmp_buf here;
    jmp_buf *volatile outer = ode_jump;
    if (setjmp(here)) {
        ode_jump = outer;
        step_memory_untracked(0);
        if (quarantine_objects(w) && (op == ODE_RESET || op == ODE_STEP))
            (void)ode_guard(w, ODE_BUILD, NULL);
        return PD_ERR_NO_CONVERGENCE;
    }
    ode_jump = &here;
    pd_status st = PD_OK;
    if (op == ODE_FREE)
        ode_objects_free(w);
    else if (op == ODE_BUILD)
        st = ode_objects_build(w) ? PD_OK : PD_ERR_NOMEM;
    else if (!w->body)
        st = PD_ERR_NO_CONVERGENCE; /* lost to an earlier failure */
    else if (op == ODE_RESET)
        st = ode_reset_body(w, s) ? PD_OK : PD_ERR_NONFINITE;
    else
        st = ode_step_body(w, s);
    ode_jump = outer;
    return st;
}

static void world_free(pd_engine_world *w)
{
    if (!w)
        return;
    if (!w->lost)
        (void)ode_guard(w, ODE_FREE, NULL);
    free(w->points);
    free(w->cand);
    free(w->mind);
    free(w->touch);
    free(w);
}

/* The power of two nearest x > 0 (in the log). */
static double pow2_near(double x)
{
    int e;
    double f = frexp(x, &e); /* x = f 2^e, 0.5 <= f < 1 */
    return ldexp(1.0, f < M_SQRT1_2 ? e - 1 : e);
}

/* Drilling friction: a contact is a patch, not a point, and Coulomb
 * friction over a disc of radius a under a normal force N resists a spin
 * about the floor's normal with a couple of at most (2/3) mu N a (uniform
 * pressure). Without it a part spinning on a corner keeps its spin: a flat
 * pyramid upside down on its apex spun at 7.5 rad/s until the time limit
 * (23 of 200 drops). The patch is the one a corner of radius R pressed as
 * deep as the contact sinks under the part's weight makes, a = sqrt(R d):
 * d = g / omega^2 with the scene's law, PD_ODE_SINK_REL L with ODE's own;
 * R = PD_CORNER_RADIUS_REL L. ODE's spinning friction (rhoN, with
 * dContactApprox1 a multiple of the normal force) is that couple's arm.
 * omega is the linear spring-dashpot's for T and e (pd_engine_contact_law),
 * the engines' law until 2026-12-07, not the Hunt-Crossley law's they now
 * stand for, whose omega for the same T is higher (3.59 / T against
 * 2.42 / T at e = 0.3), its sink 2.2 times less and its couple 1.48 times
 * weaker: with that one, Bullet's tops on the flat pyramid of
 * test_hard_parts.c spun past the time limit (docs/engines.md). The impulse
 * simulator's patch is the weaker one (sim_model.c). */
static void drilling_arm(pd_engine_world *w)
{
    double d = w->compliant ? w->gscale / (w->patch_omega * w->patch_omega)
                            : PD_ODE_SINK_REL * w->size;
    w->drill = 2.0 / 3.0 * w->mu * sqrt(PD_CORNER_RADIUS_REL * w->size * d);
}

/* The contact's material; w->dt * w->time is the step in s exactly (a
 * power of two apart). */
static pd_status material(pd_engine_world *w, const pd_scene *scene)
{
    w->mu = scene->mu;
    w->restitution = scene->restitution;
    double dt = w->dt * w->time;
    w->omega = w->chi = 0.0;
    w->compliant = 0;
    w->v_rest = 2.0 * sqrt(2.0 * w->gscale * PD_TOL_REST_FALL_REL * w->size);
    if (scene->contact_time > 0.0) {
        pd_engine_hc_law(scene->contact_time / w->time, scene->restitution, &w->omega, &w->chi);
        double zeta;
        pd_engine_contact_law(scene->contact_time / w->time, scene->restitution, &w->patch_omega,
                              &zeta);
        w->compliant = pd_engine_contact_resolved(dt, scene->contact_time, w->omega / w->time,
                                                  pd_engine_fall_speed(scene, w->size_m),
                                                  w->width_m);
    }
    drilling_arm(w);
    w->slide_speed = PD_ENGINE_SLIDE_STEPS * w->mu * w->gscale * w->dt;
    return PD_OK;
}

static pd_engine_world *world_alloc(const pd_body *body, const pd_hull *hull,
                                    const pd_scene *scene, double dt)
{
    if (!body || !hull || !scene || !(dt > 0.0) || !isfinite(dt) || hull->nverts != body->nverts ||
        hull->nfacets < 4 || !(body->mass > 0.0) || !(body->size > 0.0))
        return NULL;
    if (pthread_once(&ode_once, ode_init) != 0 || !ode_ready)
        return NULL;
    /* ODE keeps per-thread collision data; each thread that steps a world
     * must have it, and asking again in the same thread is a no-op. */
    if (!dAllocateODEDataForThread(dAllocateMaskAll))
        return NULL;
    pd_engine_world *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    double g = scale_gravity(scene);
    /* Units near the part's size, mass and sqrt(L/g), rounded to powers of
     * two so that converting to and from them is exact. */
    double munit = pow2_near(body->mass);
    w->len = pow2_near(body->size);
    w->time = pow2_near(sqrt(body->size / g));
    w->vel = w->len / w->time;
    w->mass = body->mass / munit;
    for (int k = 0; k < 3; k++)
        w->moment[k] = body->moment[k] / (munit * w->len * w->len);
    double acc = w->len / (w->time * w->time);
    w->gravity = scene->gravity / acc;
    w->dt = dt / w->time;
    double gs = g / acc, size = body->size / w->len;
    w->bounce_vel = PD_ODE_BOUNCE_VEL_REL * sqrt(gs * size);
    contact_softness(w, gs, size);
    w->size_m = body->size;
    w->width_m = pd_engine_hull_width(hull);
    w->gscale = gs;
    w->size = size;
    material(w, scene);
    if (!build_points(w, body) || ode_guard(w, ODE_BUILD, NULL) != PD_OK) {
        world_free(w);
        return NULL;
    }
    return w;
}

static int state_finite(const pd_state *s)
{
    return v3_isfinite(s->x) && v3_isfinite(s->v) && v3_isfinite(s->w) && isfinite(s->q.w) &&
           isfinite(s->q.x) && isfinite(s->q.y) && isfinite(s->q.z);
}

/* Puts the body in state s (SI units, checked finite); 0 if the state in
 * ODE's units is not finite. */
static int ode_reset_body(pd_engine_world *w, const pd_state *s)
{
    pd_vec3 x = v3_scale(s->x, 1.0 / w->len), v = v3_scale(s->v, 1.0 / w->vel);
    /* ODE's angular velocity is in the world frame, pd_state's in the body's. */
    pd_vec3 ww = v3_scale(quat_rotate(s->q, s->w), w->time);
    if (!v3_isfinite(x) || !v3_isfinite(v) || !v3_isfinite(ww))
        return 0;
    dJointGroupEmpty(w->contacts);
    dBodySetPosition(w->body, x.x, x.y, x.z);
    dQuaternion q = {s->q.w, s->q.x, s->q.y, s->q.z};
    dBodySetQuaternion(w->body, q);
    dBodySetLinearVel(w->body, v.x, v.y, v.z);
    dBodySetAngularVel(w->body, ww.x, ww.y, ww.z);
    dBodySetForce(w->body, 0.0, 0.0, 0.0);
    dBodySetTorque(w->body, 0.0, 0.0, 0.0);
    dBodyEnable(w->body);
    memset(w->touch, 0, sizeof *w->touch * (size_t)w->npoints);
    return 1;
}

static pd_status reset(pd_engine_world *w, const pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    if (!state_finite(s))
        return PD_ERR_NONFINITE;
    /* ODE normalises the quaternion and fails on a zero one. */
    if (!(quat_norm(s->q) > 0.0))
        return PD_ERR_USAGE;
    return ode_guard(w, ODE_RESET, (pd_state *)s);
}

static double plane_dist2(const dContactGeom *a, const dContactGeom *b)
{
    double dx = a->pos[0] - b->pos[0], dy = a->pos[1] - b->pos[1];
    return dx * dx + dy * dy;
}

/* Keeps at most PD_ODE_MAX_CONTACTS of the n candidates, moved to the front:
 * the deepest first, then each time the one farthest (in the floor plane)
 * from those kept, so the kept points span the touching facet. Ties go to the
 * lower index, so the choice is deterministic. */
static int select_contacts(dContactGeom *c, double *mind, int n)
{
    if (n <= PD_ODE_MAX_CONTACTS)
        return n;
    int best = 0;
    for (int i = 1; i < n; i++)
        if (c[i].depth > c[best].depth)
            best = i;
    dContactGeom t = c[0];
    c[0] = c[best];
    c[best] = t;
    for (int i = 1; i < n; i++)
        mind[i] = plane_dist2(&c[i], &c[0]);
    for (int k = 1; k < PD_ODE_MAX_CONTACTS; k++) {
        best = k;
        for (int i = k + 1; i < n; i++)
            if (mind[i] > mind[best])
                best = i;
        t = c[k];
        c[k] = c[best];
        c[best] = t;
        double md = mind[k];
        mind[k] = mind[best];
        mind[best] = md;
        for (int i = k + 1; i < n; i++) {
            double d = plane_dist2(&c[i], &c[k]);
            if (d < mind[i])
                mind[i] = d;
        }
    }
    return PD_ODE_MAX_CONTACTS;
}

/* The floor's contacts: every hull vertex below z = 0, in index order, at
 * the vertex, with its depth below the floor and the floor's normal. The
 * floor is a half-space, so a part wholly below it (landing faster than its
 * thickness per step) still meets it at every vertex; ODE's convex-plane
 * test reports nothing then (it looks for a surface crossing), and a thin
 * part fell through the floor for good. */
static int floor_contacts(const pd_engine_world *w, dContactGeom *c)
{
    const dReal *x = dBodyGetPosition(w->body);
    const dReal *R = dBodyGetRotation(w->body); /* 3 x 4, row-major */
    int n = 0;
    for (int i = 0; i < w->npoints; i++) {
        pd_vec3 p = w->points[i];
        double px = R[0] * p.x + R[1] * p.y + R[2] * p.z + x[0];
        double py = R[4] * p.x + R[5] * p.y + R[6] * p.z + x[1];
        double pz = R[8] * p.x + R[9] * p.y + R[10] * p.z + x[2];
        if (!(pz <= 0.0))
            continue;
        memset(&c[n], 0, sizeof c[n]);
        c[n].pos[0] = px;
        c[n].pos[1] = py;
        c[n].pos[2] = pz;
        c[n].normal[2] = 1.0;
        c[n].depth = -pz;
        c[n].side1 = i; /* the vertex, for its touch speed */
        n++;
    }
    return n;
}

/* The scene's law at contact g (world, ODE's units) as ODE's erp and cfm:
 * stiffness k = m_eff omega^2 for the contact's effective mass along the
 * floor's normal z, 1 / m_eff = 1/m + (r x z) . I^-1 (r x z), r from the
 * centre of mass, and the Hunt-Crossley damping c = k chi d / v0 at its
 * depth d, v0 its approach speed at touch (pd_engine_hc_law), both taken
 * at the step's start. ODE's row with erp and cfm pushes with
 * (erp d / h - u) / cfm, u the separation speed at the step's end; with
 * erp = h k / b and cfm = 1 / b that is k d + b d', the spring at the
 * step's start and the damper at its end, for b = c (plus
 * PD_ENGINE_SPRING_IMPLICIT h k, which keeps cfm finite), where ODE's own
 * form, b = h k + c, steps the spring implicitly and loses a share of the
 * rebound of order omega h (engines_tol.h). No bounce on top: the
 * damping's loss is the restitution. */
static void compliant_softness(const pd_engine_world *w, const dContactGeom *g, dReal *erp,
                               dReal *cfm)
{
    const dReal *p = g->pos;
    const dReal *x = dBodyGetPosition(w->body);
    const dReal *R = dBodyGetRotation(w->body); /* 3 x 4, row-major: body -> world */
    double ux = p[1] - x[1], uy = -(p[0] - x[0]); /* r x z, world; its z is 0 */
    double inv = 1.0 / w->mass;
    for (int i = 0; i < 3; i++) {
        double ub = R[4 * 0 + i] * ux + R[4 * 1 + i] * uy; /* (R^T u)_i */
        inv += ub * ub / w->moment[i];
    }
    double m = 1.0 / inv, h = w->dt;
    double k = m * w->omega * w->omega, c = k * w->chi * g->depth / fabs(w->touch[g->side1]);
    double b = c + PD_ENGINE_SPRING_IMPLICIT * h * k;
    *erp = h * k / b;
    *cfm = 1.0 / b;
}

/* Each vertex's approach speed at the start of its impact (at least
 * v_rest), negative once it recedes, 0 above the floor; c[0..n) are the
 * vertices below the floor. An impact starts when a vertex goes below the
 * floor, and again when one still below approaches after it receded (a
 * resting part rocking on it): each compression is an impact of its own
 * speed, as in the impulse simulator, whose impacts end when the part
 * separates or rests, so that a vertex landing fast and then resting is
 * not left with the little damping of its landing. */
static void touch_speeds(pd_engine_world *w, const dContactGeom *c, int n)
{
    for (int i = 0; i < n; i++)
        w->mind[c[i].side1] = w->touch[c[i].side1];
    memset(w->touch, 0, sizeof *w->touch * (size_t)w->npoints);
    for (int i = 0; i < n; i++) {
        int v = c[i].side1;
        dVector3 pv;
        dBodyGetPointVel(w->body, c[i].pos[0], c[i].pos[1], c[i].pos[2], pv);
        double was = w->mind[v], in = -pv[2];
        if (was == 0.0 || (was < 0.0 && in > 0.0))
            w->touch[v] = fmax(in, w->v_rest);
        else
            w->touch[v] = in < 0.0 ? -fabs(was) : was;
    }
}

static pd_status ode_step_body(pd_engine_world *w, pd_state *s)
{
    dContactGeom *cg = w->cand;
    int below = floor_contacts(w, cg);
    if (w->compliant)
        touch_speeds(w, cg, below);
    int n = select_contacts(cg, w->mind, below);
    for (int i = 0; i < n; i++) {
        dContact c;
        memset(&c, 0, sizeof c);
        c.geom = cg[i];
        /* Friction pyramid's first axis along the slip (see the top). The
         * contact normal points from the floor into the part, +z. A
         * sliding contact has friction along that axis only (mu2 = 0). */
        dVector3 pv;
        dBodyGetPointVel(w->body, cg[i].pos[0], cg[i].pos[1], cg[i].pos[2], pv);
        double tx = pv[0], ty = pv[1];
        double ts = sqrt(tx * tx + ty * ty);
        c.surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM | dContactMu2;
        c.surface.mu = w->mu;
        c.surface.mu2 = ts > w->slide_speed ? 0.0 : w->mu;
        if (ts > 0.0) {
            c.surface.mode |= dContactFDir1;
            c.fdir1[0] = tx / ts;
            c.fdir1[1] = ty / ts;
            c.fdir1[2] = 0.0;
        }
        if (w->drill > 0.0) {
            /* Spinning friction alone: rhoN is read only with the axes'
             * own coefficients (dContactAxisDep, the same flag as
             * dContactMu2), and no rolling resistance (rho = rho2 = 0). */
            c.surface.mode |= dContactRolling;
            c.surface.rhoN = w->drill;
        }
        if (w->compliant) {
            compliant_softness(w, &cg[i], &c.surface.soft_erp, &c.surface.soft_cfm);
        } else {
            c.surface.mode |= dContactBounce;
            c.surface.bounce = w->restitution;
            c.surface.bounce_vel = w->bounce_vel;
            c.surface.soft_erp = w->erp;
            c.surface.soft_cfm = w->cfm;
        }
        dJointID j = dJointCreateContact(w->world, w->contacts, &c);
        if (!j) {
            dJointGroupEmpty(w->contacts);
            return PD_ERR_NOMEM;
        }
        dJointAttach(j, w->body, NULL);
    }
    step_memory_untracked(1);
    int ok = dWorldStep(w->world, w->dt);
    step_memory_untracked(0);
    dJointGroupEmpty(w->contacts);
    if (!ok)
        return PD_ERR_NOMEM;

    const dReal *x = dBodyGetPosition(w->body);
    const dReal *q = dBodyGetQuaternion(w->body);
    const dReal *v = dBodyGetLinearVel(w->body);
    const dReal *av = dBodyGetAngularVel(w->body);
    pd_state r;
    r.x = v3_scale(v3(x[0], x[1], x[2]), w->len);
    r.q = quat(q[0], q[1], q[2], q[3]);
    r.v = v3_scale(v3(v[0], v[1], v[2]), w->vel);
    r.w = v3_scale(quat_rotate_inv(r.q, v3(av[0], av[1], av[2])), 1.0 / w->time);
    if (!state_finite(&r))
        return PD_ERR_NONFINITE;
    *s = r;
    return PD_OK;
}

static pd_status step(pd_engine_world *w, pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    return ode_guard(w, ODE_STEP, s);
}

const pd_engine pd_engine_ode = {"ode", world_alloc, world_free, material, reset, step, NULL};
