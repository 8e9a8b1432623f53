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
 * - the floor's contacts are every hull vertex near it (hull_floor_algorithm),
 *   not Bullet's support vertex and its probes;
 * - one fixed step per call, without interpolation;
 * - no deactivation: the drop loop decides rest by energy, never Bullet;
 * - the gyroscopic term by the adapter (gyroscopic_step); two friction
 *   directions, except in a step where every contact slides
 *   (friction_directions);
 * - restitution threshold PD_BULLET_BOUNCE_STEPS * g dt instead of an
 *   absolute 0.2 m/s; penetration recovered by split impulse only, so
 *   pushing a sunk part out adds no kinetic energy that the rest test would
 *   count. */
#include <cfloat>
#include <cmath>
#include <algorithm>
#include <new>

#include <btBulletDynamicsCommon.h>

extern "C" {
#include "engines/engine.h"
#include "engines/engine_contact.h"
#include "posedrop/bullet.h"
#include "engines/engines_tol.h"
#include "base/base_tol.h"
#include "posedrop/version.h"
#include "posedrop/tolerances.h"
}

/* The hull against the floor: every hull vertex within the manifold's
 * contact threshold of the plane becomes a contact point, and the manifold
 * keeps Bullet's four (the deepest, then the largest area). Bullet's own
 * convex-plane algorithm finds one point (the support vertex) per step, and
 * its option to probe more rotates the part about two axes it computes in the
 * world (perpendicular to the plane's normal) but applies in the part's own
 * frame: the probes then find a facet's corners when the part's z axis points
 * down and miss some when its x or y axis does, so landing flat sticks on
 * some faces more than on others (a cube: faces +-z 0.19, +-x 0.14 of 3000
 * drops). The vertices' heights depend only on where they are, so this
 * contact set is the same whichever way the part's frame is turned. */
/* The scene's contact law (contact_time > 0, resolved by the step;
 * engine.h): every contact the impulse simulator's Hunt-Crossley law for its
 * own effective mass (pd_engine_hc_law). */
struct contact_law {
    bool on;
    double omega, chi;
    /* The speed of resting contact's fall (the impulse simulator's,
     * settle.c), m/s: the least approach speed the damping is divided by. */
    double v_rest;
    /* Per hull vertex, the approach speed of its impact under way (at
     * least v_rest; negative once it recedes), 0 while it is above the
     * floor (touch below). */
    double *touch = nullptr;
    size_t ntouch = 0;
    double reach; /* the manifold's contact breaking threshold, m */
    double h;     /* the step, s */
    /* A contact slipping faster than this (m/s) slides through the step
     * (slide_speed); the solver info whose friction directions
     * processCollision sets for the step from that. */
    double slide;
    btContactSolverInfo *info;
};

class hull_floor_algorithm : public btActivatingCollisionAlgorithm {
    btPersistentManifold *manifold;
    const contact_law *law;

    /* The point's erp and cfm, as ODE's adapter sets its rows'
     * (compliant_softness in engine_ode.c says why): erp = h k / b and
     * cfm = 1 / b, b = c + PD_ENGINE_SPRING_IMPLICIT h k, so that the row
     * pushes with k d + b d', the spring at the step's start and the damper
     * at its end; Bullet's stiffness-and-damping form would take b = h k + c
     * and step the spring implicitly. k = m_eff omega^2, the effective mass
     * along the normal Bullet's impulse denominator's inverse, and the
     * Hunt-Crossley damping c = k chi d / v0 at the point's depth d (at the
     * step's start), v0 its vertex's approach speed at touch (the point's
     * m_index0: the manifold's first body is the hull). */
    void set_springs(const btRigidBody *body, const btVector3 &n)
    {
        for (int j = 0; j < manifold->getNumContacts(); j++) {
            btManifoldPoint &p = manifold->getContactPoint(j);
            btVector3 pa = manifold->getBody0() == body ? p.getPositionWorldOnA()
                                                        : p.getPositionWorldOnB();
            double m = 1.0 / double(body->computeImpulseDenominator(pa, n));
            double k = m * law->omega * law->omega, depth = -double(p.getDistance()), c = 0.0;
            int v = p.m_index0;
            double v0 = v >= 0 && size_t(v) < law->ntouch ? fabs(law->touch[v]) : 0.0;
            if (depth > 0.0)
                c = k * law->chi * depth / (v0 > 0.0 ? v0 : law->v_rest);
            double b = c + PD_ENGINE_SPRING_IMPLICIT * law->h * k;
            p.m_contactCFM = btScalar(1.0 / b);
            p.m_contactERP = btScalar(law->h * k / b);
            p.m_contactPointFlags &= ~BT_CONTACT_FLAG_CONTACT_STIFFNESS_DAMPING;
            p.m_contactPointFlags |= BT_CONTACT_FLAG_HAS_CONTACT_CFM | BT_CONTACT_FLAG_HAS_CONTACT_ERP;
        }
    }

    /* Bullet's friction acts along the slip alone, or along it and across
     * it (SOLVER_USE_2_FRICTION_DIRECTIONS), each row within mu times the
     * normal impulse, for the whole step's solve. Across a sliding contact
     * the second row holds the slip's direction fixed with up to mu N more
     * (a sliding impact's friction up to sqrt(2) mu N, and the slip never
     * turned); without it a resting part creeps sideways (see
     * bullet_world_alloc). So the step has both rows when a contact slips
     * slower than law->slide (it sticks, or may start to), and the slip's
     * row alone when every contact slides, as this is solved after the
     * collisions are found, in the same step. */
    void friction_directions(const btRigidBody *body, const btVector3 &n)
    {
        bool slow = false;
        for (int j = 0; j < manifold->getNumContacts(); j++) {
            btManifoldPoint &p = manifold->getContactPoint(j);
            btVector3 pa = manifold->getBody0() == body ? p.getPositionWorldOnA()
                                                        : p.getPositionWorldOnB();
            btVector3 v = body->getVelocityInLocalPoint(pa - body->getCenterOfMassPosition());
            btVector3 t = v - n * n.dot(v);
            slow = slow || double(t.length()) <= law->slide;
        }
        if (slow)
            law->info->m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
        else
            law->info->m_solverMode &= ~SOLVER_USE_2_FRICTION_DIRECTIONS;
    }

    /* Vertex i at p, d from the floor along n: the approach speed of its
     * impact (at least v_rest; negative once it recedes), 0 above the
     * floor. An impact starts when the vertex goes below the floor, and
     * again when it approaches after it receded while still below, as
     * ODE's adapter has it (touch_speeds in engine_ode.c says why). */
    void touch(const btRigidBody *body, int i, const btVector3 &p, const btVector3 &n, double d)
    {
        if (!law->on || !body || size_t(i) >= law->ntouch)
            return;
        double &v0 = law->touch[size_t(i)];
        if (d >= 0.0) {
            v0 = 0.0;
            return;
        }
        btVector3 v = body->getVelocityInLocalPoint(p - body->getCenterOfMassPosition());
        double in = -double(n.dot(v));
        if (v0 == 0.0 || (v0 < 0.0 && in > 0.0))
            v0 = fmax(in, law->v_rest);
        else if (in < 0.0)
            v0 = -fabs(v0);
    }

    /* A vertex within reach of the floor: where it is, its distance, and
     * (select_points) its squared distance in the floor's plane from the
     * points chosen so far. */
    struct point {
        int vertex;
        btVector3 p;
        btScalar d;
        btScalar far2;
    };
    btAlignedObjectArray<point> cand;

    /* Keeps at most MANIFOLD_CACHE_SIZE of the n candidates, moved to the
     * front, as ODE's adapter chooses its points (select_contacts in
     * engine_ode.c): the deepest, then each time the one farthest in the
     * floor's plane from those kept, ties to the lower vertex. A face's
     * corners are then spread over it, symmetrically about its centre on a
     * regular polygon, where the manifold's own rule (keep the deepest,
     * then the largest area, point by point in the order found) kept four
     * of a 32-gon's corners off its centre, whose pushes spun the disc
     * landing flat and moved its rebound by up to 0.16 of the approach
     * speed at 160 steps a contact (test_face_and_edge). */
    int select_points(int n, const btVector3 &normal)
    {
        if (n <= MANIFOLD_CACHE_SIZE || !law->on)
            return n;
        int best = 0;
        for (int i = 1; i < n; i++)
            if (cand[i].d < cand[best].d)
                best = i;
        cand.swap(0, best);
        for (int i = 1; i < n; i++)
            cand[i].far2 = plane_dist2(cand[i].p, cand[0].p, normal);
        for (int k = 1; k < MANIFOLD_CACHE_SIZE; k++) {
            best = k;
            for (int i = k + 1; i < n; i++)
                if (cand[i].far2 > cand[best].far2 ||
                    (cand[i].far2 == cand[best].far2 && cand[i].vertex < cand[best].vertex))
                    best = i;
            cand.swap(k, best);
            for (int i = k + 1; i < n; i++)
                cand[i].far2 = std::min(cand[i].far2, plane_dist2(cand[i].p, cand[k].p, normal));
        }
        return MANIFOLD_CACHE_SIZE;
    }

    static btScalar plane_dist2(const btVector3 &a, const btVector3 &b, const btVector3 &normal)
    {
        btVector3 d = a - b;
        d -= normal * normal.dot(d);
        return d.length2();
    }

public:
    hull_floor_algorithm(const btCollisionAlgorithmConstructionInfo &ci,
                         const btCollisionObjectWrapper *a, const btCollisionObjectWrapper *b,
                         const contact_law *contact)
        : btActivatingCollisionAlgorithm(ci, a, b), manifold(nullptr), law(contact)
    {
    }

    ~hull_floor_algorithm() override
    {
        if (manifold)
            m_dispatcher->releaseManifold(manifold);
    }

    void processCollision(const btCollisionObjectWrapper *a, const btCollisionObjectWrapper *b,
                          const btDispatcherInfo &, btManifoldResult *out) override
    {
        bool swapped = a->getCollisionShape()->getShapeType() == STATIC_PLANE_PROXYTYPE;
        const btCollisionObjectWrapper *hw = swapped ? b : a, *pw = swapped ? a : b;
        const btConvexHullShape *hull =
            static_cast<const btConvexHullShape *>(hw->getCollisionShape());
        const btStaticPlaneShape *plane =
            static_cast<const btStaticPlaneShape *>(pw->getCollisionShape());
        if (!manifold) {
            manifold =
                m_dispatcher->getNewManifold(hw->getCollisionObject(), pw->getCollisionObject());
            manifold->setContactBreakingThreshold(btScalar(law->reach));
        }
        out->setPersistentManifold(manifold);

        const btTransform &th = hw->getWorldTransform(), &tp = pw->getWorldTransform();
        btVector3 n = tp.getBasis() * plane->getPlaneNormal();
        btScalar c = plane->getPlaneConstant() + n.dot(tp.getOrigin());
        /* The shape is the hull inflated by its margin, the plane lowered by
         * as much (see bullet_world_alloc): a vertex's distance is that of
         * its inflated sphere's lowest point. */
        btScalar margin = hull->getMargin();
        btScalar reach = manifold->getContactBreakingThreshold();
        const btRigidBody *body = btRigidBody::upcast(hw->getCollisionObject());
        int np = hull->getNumPoints();
        cand.resize(size_t(np));
        int nc = 0;
        for (int i = 0; i < np; i++) {
            btVector3 p = th(hull->getScaledPoint(i)) - margin * n;
            btScalar d = n.dot(p) - c;
            touch(body, i, p, n, double(d));
            if (d < reach)
                cand[size_t(nc++)] = {i, p, d, 0};
        }
        nc = select_points(nc, n);
        /* Under the scene's law the manifold keeps the points chosen only,
         * so that it does not choose among more by its own rule; a vertex
         * chosen again matches its point (within the breaking threshold),
         * whose impulses then warm-start the solver as before. The engine's
         * own contact (law off) keeps the manifold's rule: with the choice
         * above, which moves between a resting face's corners as their
         * depths waver, a flat pyramid and a needle at 1/960 s no longer
         * settled (3 of 200 and 9 of 100 drops, test_hard_parts.c). */
        for (int j = law->on ? manifold->getNumContacts() - 1 : -1; j >= 0; j--) {
            int v = manifold->getContactPoint(j).m_index0;
            bool kept = false;
            for (int k = 0; k < nc; k++)
                kept = kept || cand[size_t(k)].vertex == v;
            if (!kept)
                manifold->removeContactPoint(j);
        }
        for (int k = 0; k < nc; k++) {
            const point &q = cand[size_t(k)];
            /* The vertex, for its touch speed (set_springs). */
            if (swapped)
                out->setShapeIdentifiersB(-1, q.vertex);
            else
                out->setShapeIdentifiersA(-1, q.vertex);
            out->addContactPoint(n, q.p - q.d * n, q.d);
        }
        out->refreshContactPoints();
        if (law->on && body)
            set_springs(body, n);
        if (body)
            friction_directions(body, n);
    }

    btScalar calculateTimeOfImpact(btCollisionObject *, btCollisionObject *,
                                   const btDispatcherInfo &, btManifoldResult *) override
    {
        return btScalar(1);
    }

    void getAllContactManifolds(btManifoldArray &array) override
    {
        if (manifold)
            array.push_back(manifold);
    }
};

struct hull_floor_create : btCollisionAlgorithmCreateFunc {
    contact_law law;

    btCollisionAlgorithm *CreateCollisionAlgorithm(btCollisionAlgorithmConstructionInfo &ci,
                                                   const btCollisionObjectWrapper *a,
                                                   const btCollisionObjectWrapper *b) override
    {
        void *mem = ci.m_dispatcher1->allocateCollisionAlgorithm(sizeof(hull_floor_algorithm));
        return mem ? new (mem) hull_floor_algorithm(ci, a, b, &law) : nullptr;
    }
};

/* The unit Bullet is handed masses in: the power of two nearest the part's
 * mass (so the conversion is exact), which makes the body's mass of order 1.
 * Nothing of the motion depends on it (gravity is an acceleration, friction
 * and restitution are ratios, the contact law's springs are per effective
 * mass, and no mass is read back), but Bullet's solver has absolute limits:
 * a 300 m cube of 2.7e7 kg met the floor with its contact found and no
 * impulse applied, and fell through it (a 100 m one of 1e6 kg was held);
 * handed its mass in units of 2^25 kg (0.8 of one) it rests, and so does a
 * 1000 m cube. */
static double mass_unit(double mass)
{
    int e;
    double f = std::frexp(mass, &e); /* mass = f 2^e, 0.5 <= f < 1 */
    return std::ldexp(1.0, f < M_SQRT1_2 ? e - 1 : e);
}

struct pd_engine_world {
    btDefaultCollisionConfiguration config;
    hull_floor_create hull_floor;
    btCollisionDispatcher dispatcher;
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btDiscreteDynamicsWorld world;
    btConvexHullShape hull;
    btStaticPlaneShape floor;
    btRigidBody floor_body;
    btRigidBody body;
    btScalar dt;
    double step_s;  /* dt in s, as the scene's contact time is compared with it */
    double size_m, width_m; /* the part's size and thickness, m (pd_engine_contact_resolved) */
    pd_quat q_last; /* keeps the read-back quaternion on one hemisphere */

    pd_engine_world(const pd_body *b, double step, double width, double margin)
        : dispatcher(&config),
          world(&dispatcher, &broadphase, &solver, &config),
          hull(),
          floor(btVector3(0, 0, 1), btScalar(-margin)),
          floor_body(btRigidBody::btRigidBodyConstructionInfo(0, nullptr, &floor)),
          body(btRigidBody::btRigidBodyConstructionInfo(
              btScalar(b->mass / mass_unit(b->mass)), nullptr, &hull,
              btVector3(btScalar(b->moment[0] / mass_unit(b->mass)),
                        btScalar(b->moment[1] / mass_unit(b->mass)),
                        btScalar(b->moment[2] / mass_unit(b->mass))))),
          dt(btScalar(step)),
          step_s(step),
          size_m(b->size),
          width_m(width),
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

/* The manifold's contact breaking threshold. Bullet's own is 0.02 of the
 * shape's bounding radius, and the manifold takes a new point within that
 * distance of a kept one for the same point: on a 1 m x 1 cm x 1 cm rod
 * (threshold 1 cm) the corners of an end face merged, the rod could not lie
 * on a face, rolled onto an edge and sank into the floor. A quarter of the
 * shortest distance between two hull vertices keeps every corner apart;
 * Bullet's value is kept when smaller. */
static double contact_reach(const btConvexHullShape &hull)
{
    double d2 = INFINITY;
    for (int i = 0; i < hull.getNumPoints(); i++)
        for (int j = i + 1; j < hull.getNumPoints(); j++)
            d2 = fmin(d2, double(hull.getScaledPoint(i).distance2(hull.getScaledPoint(j))));
    double bullet = double(hull.getContactBreakingThreshold(gContactBreakingThreshold));
    return fmin(0.25 * sqrt(d2), bullet);
}

/* The contact's material, for world_alloc and for drops that draw their
 * own. */
static pd_status bullet_material(pd_engine_world *w, const pd_scene *scene)
{
    contact_law &law = w->hull_floor.law;
    law.omega = law.chi = 0.0;
    law.on = false;
    double gv = scene->gravity != 0.0 ? fabs(scene->gravity) : 9.81;
    law.v_rest = 2.0 * sqrt(2.0 * gv * PD_TOL_REST_FALL_REL * w->size_m);
    std::fill(law.touch, law.touch + law.ntouch, 0.0);
    if (scene->contact_time > 0.0) {
        pd_engine_hc_law(scene->contact_time, scene->restitution, &law.omega, &law.chi);
        law.on = pd_engine_contact_resolved(w->step_s, scene->contact_time, law.omega,
                                            pd_engine_fall_speed(scene, w->size_m),
                                            w->width_m);
    }
    /* Penetration deeper than the threshold is removed by a position-only
     * (split) impulse (see world_alloc). With the scene's spring-dashpot
     * (law.on) the penetration term is the spring's force: it must act on
     * the velocities, not only on the positions, and the rebound is the
     * dashpot's alone (no restitution). */
    w->world.getSolverInfo().m_splitImpulse = law.on ? 0 : 1;
    w->body.setFriction(btScalar(scene->mu));
    /* Sliding: PD_ENGINE_SLIDE_STEPS steps of friction under the part's
     * weight (standard gravity's without gravity, as in ODE's adapter), and
     * at least twice the slip below which Bullet does not turn the first
     * friction row along the slip (its lateral speed squared within
     * FLT_EPSILON, m^2/s^2). */
    double g = scene->gravity != 0.0 ? fabs(scene->gravity) : 9.81;
    law.slide = fmax(PD_ENGINE_SLIDE_STEPS * scene->mu * g * w->step_s,
                     2.0 * sqrt(double(FLT_EPSILON)));
    w->body.setRestitution(law.on ? btScalar(0) : btScalar(scene->restitution));
    /* Drilling friction, as ODE's adapter has it (drilling_arm in
     * engine_ode.c): a contact is a patch of radius a = sqrt(R d), a corner
     * of radius R = PD_CORNER_RADIUS_REL L pressed as deep as the scene's
     * contact sinks under the weight, d = g / omega^2, resisting a spin
     * about the floor's normal with a couple of at most (2/3) mu a N.
     * Bullet's spinning friction is that couple's arm: Bullet combines the
     * part's with the floor's friction (1) plus the floor's (0) with the
     * part's, which leaves the part's exactly. It applies it only where
     * rolling friction is on, at the first contact of a manifold: rolling
     * friction is set to 1e-30 of an arm (no rolling resistance), and a
     * face's drilling acts at one of its corners only. A rigid scene
     * (contact time 0) has no patch, as in the impulse engine. */
    double arm = 0.0;
    if (scene->contact_time > 0.0) {
        /* The patch's omega as ODE's adapter takes it (drilling_arm). */
        double patch_omega, zeta;
        pd_engine_contact_law(scene->contact_time, scene->restitution, &patch_omega, &zeta);
        arm = 2.0 / 3.0 * scene->mu * sqrt(PD_CORNER_RADIUS_REL * w->size_m * g) / patch_omega;
    }
    w->body.setSpinningFriction(btScalar(arm));
    w->body.setRollingFriction(btScalar(arm > 0.0 ? 1e-30 * arm : 0.0));
    return PD_OK;
}

/* Bullet's coordinates are single precision: a vertex is known to
 * FLT_EPSILON of its distance from the origin, and a drop's vertices are at
 * least the drop height plus the part's size from it. A part whose
 * thickness that round-off does not resolve to PD_BULLET_WIDTH_ULPS_MAX
 * cannot rest on its faces in Bullet: its contacts are blurred by a sizeable
 * share of its thickness and its margin (a thousandth of the thickness) is
 * below the round-off altogether. Measured: a 1 mm x 1 um needle
 * (round-off 1.4e-2 of its thickness) left 4 of 100 drops balanced on an
 * edge at the time limit; a flat pyramid 5 um high (3.2e-3) settled every
 * one of 200. */
static const char *bullet_refuses(const pd_body *b, const pd_hull *hull, const pd_scene *scene)
{
    if (!b || !hull || !scene)
        return nullptr;
    const pd_dist *h = &scene->range[PD_PARAM_HEIGHT];
    double height = h->kind == PD_DIST_FIXED ? scene->height : h->hi;
    double ulp = double(FLT_EPSILON) * (height + b->size);
    if (ulp > PD_BULLET_WIDTH_ULPS_MAX * pd_engine_hull_width(hull))
        return "its thickness is below what Bullet's single-precision coordinates resolve at the "
               "drop's scale (the drop height plus its size); use the ode or impulse engine";
    return nullptr;
}

static pd_engine_world *bullet_world_alloc(const pd_body *b, const pd_hull *hull,
                                           const pd_scene *scene, double dt)
{
    /* The body's vertices are already in the principal frame; the hull
     * gives the thickness. */
    if (!b || !hull || !scene || !(dt > 0.0) || b->nverts < 4 || !(b->mass > 0.0))
        return nullptr;
    double width = pd_engine_hull_width(hull);
    double margin = PD_BULLET_MARGIN_REL * fmin(b->size, width);
    pd_engine_world *w;
    try {
        w = new pd_engine_world(b, dt, width, margin);
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
    w->hull.setMargin(btScalar(margin));

    w->hull_floor.law.reach = contact_reach(w->hull);
    w->hull_floor.law.h = dt;
    w->hull_floor.law.touch = new (std::nothrow) double[size_t(b->nverts)]();
    w->hull_floor.law.ntouch = w->hull_floor.law.touch ? size_t(b->nverts) : 0;
    if (!w->hull_floor.law.touch) {
        delete w;
        return nullptr;
    }
    w->dispatcher.registerCollisionCreateFunc(CONVEX_HULL_SHAPE_PROXYTYPE, STATIC_PLANE_PROXYTYPE,
                                              &w->hull_floor);
    w->dispatcher.registerCollisionCreateFunc(STATIC_PLANE_PROXYTYPE, CONVEX_HULL_SHAPE_PROXYTYPE,
                                              &w->hull_floor);

    btContactSolverInfo &info = w->world.getSolverInfo();
    info.m_restitutionVelocityThreshold = btScalar(PD_BULLET_BOUNCE_STEPS * scene->gravity * dt);
    /* Penetration deeper than this is removed by a position-only (split)
     * impulse; Bullet's -0.04 m default sends every penetration of a small
     * part to Baumgarte velocity instead, which feeds energy in. */
    info.m_splitImpulsePenetrationThreshold = 0;
    /* Bullet's default friction acts along the sliding direction only; a
     * part resting on a face then creeps sideways at ~1e-4 m/s (measured on
     * a 1 x 2 x 3 cm box), a second, orthogonal direction holds it (2e-6 m
     * in 1 s). It is kept for every step in which a contact slips slowly,
     * and left out while all slide (hull_floor_algorithm's
     * friction_directions). */
    info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
    w->hull_floor.law.info = &info;

    w->world.setGravity(btVector3(0, 0, btScalar(-scene->gravity)));

    w->floor_body.setFriction(1);
    w->floor_body.setRestitution(1);
    bullet_material(w, scene);
    w->body.setActivationState(DISABLE_DEACTIVATION);
    w->body.setSleepingThresholds(0, 0);
    w->body.setDamping(0, 0);
    /* The gyroscopic term is applied by bullet_step (gyroscopic_step), not
     * by Bullet (flags 0): Bullet's implicit one is applied by the contact
     * solver only, which skips a body without contacts (in flight the world
     * angular velocity then stays constant and a tumbling part's angular
     * momentum drifts by 17% in 0.1 s), and is zero for a small part anyway
     * (its 3 x 3 solve refuses a determinant below 1.2e-7, and a 1 cm part's
     * is ~1e-27); its explicit one is forward Euler, unstable once |w| dt is
     * of order 1 (a 0.01 mm flake spun to 3750 rad/s by a bounce, 3.9 rad
     * per step, gained 1e29 times its energy). */
    w->body.setFlags(0);

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
    delete[] w->hull_floor.law.touch;
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
    std::fill(w->hull_floor.law.touch, w->hull_floor.law.touch + w->hull_floor.law.ntouch, 0.0);
    w->q_last = q;
    return PD_OK;
}

/* Euler's equations for the torque-free part over one step, I w' = -w x I w
 * in the body frame, by one Newton step of backward Euler (Bullet's own
 * scheme, computed here in double precision and without its absolute
 * determinant test): solve I (x - w) + dt x x I x = 0 from x = w. Stable at
 * any |w| dt, first order; applied before the step, as Bullet's solver
 * applies external impulses before the contacts. */
static void gyroscopic_step(pd_engine_world *w)
{
    btRigidBody &b = w->body;
    const btMatrix3x3 &R = b.getCenterOfMassTransform().getBasis();
    btVector3 ww = b.getAngularVelocity();
    double I[3], om[3], Io[3], f[3], J[3][3];
    btVector3 inertia = b.getLocalInertia();
    for (int i = 0; i < 3; i++) {
        I[i] = double(inertia[i]);
        om[i] = double(R[0][i]) * double(ww.x()) + double(R[1][i]) * double(ww.y()) +
                double(R[2][i]) * double(ww.z()); /* R^T w */
        Io[i] = I[i] * om[i];
    }
    double h = double(w->dt);
    for (int i = 0; i < 3; i++) {
        int j = (i + 1) % 3, k = (i + 2) % 3;
        f[i] = h * (om[j] * Io[k] - om[k] * Io[j]);
        /* d/dx of h x x I x: row i, columns j and k (the diagonal is 0). */
        J[i][i] = I[i];
        J[i][j] = h * (-om[k] * I[j] + Io[k]);
        J[i][k] = h * (om[j] * I[k] - Io[j]);
    }
    double det = J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) -
                 J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
                 J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
    if (!(fabs(det) > 0.0) || !std::isfinite(det))
        return;
    double d[3];
    for (int c = 0; c < 3; c++) { /* Cramer: column c replaced by f */
        double M[3][3];
        for (int r = 0; r < 3; r++)
            for (int q = 0; q < 3; q++)
                M[r][q] = q == c ? f[r] : J[r][q];
        d[c] = (M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) -
                M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0])) /
               det;
    }
    for (int i = 0; i < 3; i++)
        om[i] -= d[i];
    btVector3 nw;
    for (int i = 0; i < 3; i++)
        nw[i] = btScalar(double(R[i][0]) * om[0] + double(R[i][1]) * om[1] +
                         double(R[i][2]) * om[2]);
    b.setAngularVelocity(nw);
}

static pd_status bullet_step(pd_engine_world *w, pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    gyroscopic_step(w);
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
    bullet_material,
    bullet_reset,
    bullet_step,
    bullet_refuses,
};

extern "C" pd_status pd_bullet_register(void)
{
    return pd_engine_register(PD_ENGINE_BULLET, &pd_engine_bullet, PD_VERSION_STRING);
}
