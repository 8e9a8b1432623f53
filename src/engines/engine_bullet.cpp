/* engine_bullet.cpp: the Bullet stepping engine behind engine.h.
 *
 * The project's only C++ file and the only one that sees Bullet's headers, so
 * everything else stays C11. One btDiscreteDynamicsWorld per pd_engine_world
 * (its own broadphase, dispatcher, solver and collision configuration, so
 * worlds on different threads share nothing of ours).
 *
 * Modelling choices, each against a Bullet default that is wrong for small
 * parts or for a cross-check:
 * - the rigid body's frame is the principal frame with its origin at the
 *   centre of mass, so pd_state maps onto the btTransform one to one and the
 *   local inertia is diagonal: the true principal moments are set (Bullet's
 *   own estimate for a hull is that of its bounding box);
 * - the margin is PD_BULLET_MARGIN_REL of the part's size, and the floor
 *   plane is lowered by it (see bullet_world_alloc) so that the hull's true corners,
 *   not the inflated ones, rest on z = 0;
 * - friction and restitution: Bullet multiplies the two bodies' values, so
 *   the floor's are 1 and the part's are the scene's (exact: 1 * x == x);
 * - one fixed step per call, without interpolation;
 * - no deactivation: the drop loop decides rest by energy, never Bullet;
 * - explicit gyroscopic torque and two friction directions (bullet_world_alloc);
 * - restitution threshold PD_BULLET_BOUNCE_STEPS * g dt instead of an
 *   absolute 0.2 m/s; penetration recovered by split impulse only, so
 *   pushing a sunk part out adds no kinetic energy that the rest test would
 *   count. */
#include <cmath>
#include <new>

#include <btBulletDynamicsCommon.h>

extern "C" {
#include "engines/engine.h"
#include "posedrop/bullet.h"
#include "posedrop/tolerances.h"
#include "posedrop/version.h"
}

/* The convex-plane algorithm finds one contact (the support vertex) per step
 * unless asked to probe more by small rotations of the part; a face landing
 * flat then starts on one corner and tips about it. Asking for more points
 * whenever the manifold holds fewer than this (of Bullet's 4) gets the whole
 * face in the step it lands. */
static const int BULLET_PLANE_PROBES = 4;
static const int BULLET_PLANE_MIN_POINTS = 3;

struct pd_engine_world {
    btDefaultCollisionConfiguration config;
    btCollisionDispatcher dispatcher;
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world;
    btConvexHullShape hull;
    btStaticPlaneShape floor;
    btRigidBody floor_body;
    btRigidBody body;
    btScalar dt;
    pd_quat q_last; /* keeps the read-back quaternion on one hemisphere */

    pd_engine_world(const pd_body *b, double step)
        : dispatcher(&config),
          world(&dispatcher, &broadphase, &solver, &config),
          hull(),
          floor(btVector3(0, 0, 1), btScalar(-PD_BULLET_MARGIN_REL * b->size)),
          floor_body(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &floor)),
          body(btRigidBody::btRigidBodyConstructionInfo(
              btScalar(b->mass), nullptr, &hull,
              btVector3(btScalar(b->moment[0]), btScalar(b->moment[1]), btScalar(b->moment[2])))),
          dt(btScalar(step)),
          q_last(quat_identity())
    {
    }
};

static btVector3 to_bt(pd_vec3 v)
{
    return btVector3(btScalar(v.x), btScalar(v.y), btScalar(v.z));
}

static pd_vec3 to_vec(btVector3 v)
{
    pd_vec3 r = {double(v.x()), double(v.y()), double(v.z())};
    return r;
}

static bool finite_state(const pd_state *s)
{
    const double a[13] = {s->x.x, s->x.y, s->x.z, s->q.w, s->q.x, s->q.y, s->q.z,
                          s->v.x, s->v.y, s->v.z, s->w.x, s->w.y, s->w.z};
    for (double d : a)
        if (!std::isfinite(d))
            return false;
    return true;
}

static pd_engine_world *bullet_world_alloc(const pd_body *b, const pd_hull *hull,
                                           const pd_scene *scene, double dt)
{
    (void)hull; /* the body's vertices are already in the principal frame */
    if (!b || !scene || !(dt > 0.0) || b->nverts < 4 || !(b->mass > 0.0))
        return nullptr;
    pd_engine_world *w;
    try {
        w = new pd_engine_world(b, dt);
    } catch (const std::bad_alloc &) {
        return nullptr;
    }

    for (int i = 0; i < b->nverts; i++)
        w->hull.addPoint(to_bt(b->verts[i]), false);
    w->hull.recalcLocalAabb();
    /* The part's surface in Bullet is the hull inflated by the margin; the
     * floor plane sits the same distance below z = 0 (its constructor), and
     * since the inflation is a sphere, every corner of the hull, whatever
     * the orientation, touches that plane exactly when the corner itself
     * reaches z = 0. Shrinking the hull instead would need a half-space
     * intersection and be exact only away from its corners. */
    w->hull.setMargin(btScalar(PD_BULLET_MARGIN_REL * b->size));

    w->config.setPlaneConvexMultipointIterations(BULLET_PLANE_PROBES, BULLET_PLANE_MIN_POINTS);

    btContactSolverInfo &info = w->world.getSolverInfo();
    info.m_restitutionVelocityThreshold = btScalar(PD_BULLET_BOUNCE_STEPS * scene->gravity * dt);
    /* Penetration deeper than this is removed by a position-only (split)
     * impulse; Bullet's -0.04 m default sends every penetration of a small
     * part to Baumgarte velocity instead, which feeds energy in. */
    info.m_splitImpulse = 1;
    info.m_splitImpulsePenetrationThreshold = 0;
    /* Bullet's default friction acts along the sliding direction only; a
     * part resting on a face then creeps sideways at ~1e-4 m/s (measured on
     * a 1 x 2 x 3 cm box), a second, orthogonal direction holds it (2e-6 m
     * in 1 s). */
    info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;

    w->world.setGravity(btVector3(0, 0, btScalar(-scene->gravity)));

    w->floor_body.setFriction(1);
    w->floor_body.setRestitution(1);
    w->body.setFriction(btScalar(scene->mu));
    w->body.setRestitution(btScalar(scene->restitution));
    w->body.setActivationState(DISABLE_DEACTIVATION);
    w->body.setSleepingThresholds(0, 0);
    w->body.setDamping(0, 0);
    /* Bullet's default gyroscopic term (implicit, body frame) is applied by
     * the contact solver only, which skips a body without contacts: in
     * flight the world angular velocity then stays constant and a tumbling
     * part's angular momentum drifts by 17% in 0.1 s. The explicit term is
     * applied in flight too (first order: 0.5% there). */
    w->body.setFlags(BT_ENABLE_GYROSCOPIC_FORCE_EXPLICIT);

    w->world.addRigidBody(&w->floor_body);
    w->world.addRigidBody(&w->body);
    return w;
}

static void bullet_world_free(pd_engine_world *w)
{
    if (!w)
        return;
    w->world.removeRigidBody(&w->body);
    w->world.removeRigidBody(&w->floor_body);
    delete w;
}

static pd_status bullet_reset(pd_engine_world *w, const pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    if (!finite_state(s))
        return PD_ERR_NONFINITE;
    pd_quat q = quat_normalize(s->q);
    btTransform t(btQuaternion(btScalar(q.x), btScalar(q.y), btScalar(q.z), btScalar(q.w)),
                  to_bt(s->x));
    btVector3 v = to_bt(s->v);
    btVector3 ww = to_bt(quat_rotate(q, s->w)); /* Bullet's is in the world */

    btRigidBody &b = w->body;
    b.setCenterOfMassTransform(t);
    b.setLinearVelocity(v);
    b.setAngularVelocity(ww);
    b.setInterpolationLinearVelocity(v);
    b.setInterpolationAngularVelocity(ww);
    b.clearForces();
    /* Contacts cached from a previous drop would warm-start the solver and
     * age the contact: drop them, and restart the solver's own state, so a
     * reset world steps exactly as a fresh one. */
    w->world.getBroadphase()->getOverlappingPairCache()->cleanProxyFromPairs(
        b.getBroadphaseHandle(), &w->dispatcher);
    w->world.updateSingleAabb(&b);
    w->solver.reset();
    w->q_last = q;
    return PD_OK;
}

static pd_status bullet_step(pd_engine_world *w, pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    /* maxSubSteps = 0: exactly one step of dt, and the transform read below
     * is the simulated one, not an interpolation. */
    w->world.stepSimulation(w->dt, 0, w->dt);

    const btTransform &t = w->body.getCenterOfMassTransform();
    const btMatrix3x3 &m = t.getBasis();
    double R[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            R[i][j] = double(m[i][j]);
    pd_quat q = quat_from_matrix(R);
    if (q.w * w->q_last.w + q.x * w->q_last.x + q.y * w->q_last.y + q.z * w->q_last.z < 0.0)
        q = quat(-q.w, -q.x, -q.y, -q.z);
    w->q_last = q;

    s->x = to_vec(t.getOrigin());
    s->q = q;
    s->v = to_vec(w->body.getLinearVelocity());
    s->w = quat_rotate_inv(q, to_vec(w->body.getAngularVelocity()));
    return finite_state(s) ? PD_OK : PD_ERR_NONFINITE;
}

extern "C" const pd_engine pd_engine_bullet = {
    "bullet",
    bullet_world_alloc,
    bullet_world_free,
    bullet_reset,
    bullet_step,
};

extern "C" pd_status pd_bullet_register(void)
{
    return pd_engine_register(PD_ENGINE_BULLET, &pd_engine_bullet, PD_VERSION_STRING);
}
