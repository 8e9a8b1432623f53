/* engine_ode.c: the Open Dynamics Engine backend (see engine.h). The only file
 * that includes ODE's headers.
 *
 * The ODE body's frame is the principal frame of pd_body: origin at the centre
 * of mass, axes along the principal axes. So its mass is diagonal, a
 * pd_state's position and orientation are the body's own, and the hull is
 * handed to dCreateConvex already in that frame.
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
 * along the sliding velocity, so a sliding contact meets exactly mu N against
 * its motion; only a sideways push on a sliding contact, or a stick broken
 * diagonally, sees the pyramid's up to sqrt(2) larger corner. */
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <ode/ode.h>
#include "engines/engine.h"
#include "posedrop/tolerances.h"
#include "base/vec3.h"

/* Candidate contacts asked of dCollide, from which PD_ODE_MAX_CONTACTS are
 * chosen: ODE's convex-plane test reports the hull vertices under the floor
 * in index order and stops at the buffer's size, so a small buffer would keep
 * the first corners of a facet, not a spread of them. A facet with more than
 * 64 corners is still spread over only its first 64 (in hull order). */
enum { ODE_CANDIDATES = 64 };

/* libode-dev is built in double precision (dGetConfiguration reports
 * ODE_double_precision); the states cross over without conversion and the
 * tests' round-off bounds assume it. A single-precision ODE would need its
 * own tolerances, so it is refused at compile time. */
_Static_assert(sizeof(dReal) == sizeof(double), "ODE must be built with dDOUBLE");

struct pd_engine_world {
    dWorldID world;
    dSpaceID space;
    dBodyID body;
    dGeomID convex, plane;
    dJointGroupID contacts;
    dThreadingImplementationID threading;
    /* dCreateConvex keeps pointers to these: they live as long as the geom. */
    dReal *planes;
    dReal *points;
    unsigned int *polygons;
    double dt;
    double mu, restitution, bounce_vel;
    double erp, cfm;
};

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

static void ode_close(void) { dCloseODE(); }

static void ode_init(void)
{
    if (!dInitODE2(0))
        return;
    dSetMessageHandler(ode_silent);
    /* If atexit cannot register, ODE is simply never closed: the process
     * exit reclaims it, and it stays usable until then. */
    (void)atexit(ode_close);
    ode_ready = 1;
}

static void world_free(pd_engine_world *w)
{
    if (!w)
        return;
    if (w->contacts)
        dJointGroupDestroy(w->contacts);
    if (w->convex)
        dGeomDestroy(w->convex);
    if (w->plane)
        dGeomDestroy(w->plane);
    if (w->space)
        dSpaceDestroy(w->space);
    if (w->world)
        dWorldDestroy(w->world); /* also destroys the body */
    if (w->threading)
        dThreadingFreeImplementation(w->threading);
    free(w->planes);
    free(w->points);
    free(w->polygons);
    free(w);
}

/* The hull in the principal frame, in dCreateConvex's layout: planes as
 * (a, b, c, d) with a x + b y + c z = d, points as x, y, z triples, polygons
 * as a corner count followed by the corner indices, counter-clockwise seen
 * from outside (the hull's own order; ODE's convex tests rely on it). */
static int build_convex(pd_engine_world *w, const pd_body *body, const pd_hull *hull)
{
    size_t nf = (size_t)hull->nfacets, nv = (size_t)body->nverts;
    size_t nloop = (size_t)hull->facet_start[hull->nfacets];
    w->planes = malloc(sizeof *w->planes * 4 * nf);
    w->points = malloc(sizeof *w->points * 3 * nv);
    w->polygons = malloc(sizeof *w->polygons * (nf + nloop));
    if (!w->planes || !w->points || !w->polygons)
        return 0;
    for (size_t i = 0; i < nv; i++) {
        w->points[3 * i + 0] = body->verts[i].x;
        w->points[3 * i + 1] = body->verts[i].y;
        w->points[3 * i + 2] = body->verts[i].z;
    }
    size_t k = 0;
    for (size_t f = 0; f < nf; f++) {
        /* Part frame -> principal frame: n' = frame^-1 n, and a point p' of
         * the plane is frame^-1 (p - com), so n'.p' = n.p - n.com. */
        pd_vec3 n = quat_rotate_inv(body->frame, hull->normal[f]);
        w->planes[4 * f + 0] = n.x;
        w->planes[4 * f + 1] = n.y;
        w->planes[4 * f + 2] = n.z;
        w->planes[4 * f + 3] = hull->offset[f] - v3_dot(hull->normal[f], body->com);
        int a = hull->facet_start[f], b = hull->facet_start[f + 1];
        w->polygons[k++] = (unsigned int)(b - a);
        for (int j = a; j < b; j++)
            w->polygons[k++] = (unsigned int)hull->facet_vert[j];
    }
    return 1;
}

/* With zero gravity there is no weight or fall speed to scale the contact
 * by; standard gravity's stands in. */
static double scale_gravity(const pd_scene *scene)
{
    double g = fabs(scene->gravity);
    return g > 0.0 ? g : 9.81;
}

/* Contact softness: one contact carrying the weight m g sinks
 * PD_ODE_SINK_REL * L, so kp = m g / (PD_ODE_SINK_REL L), damped at
 * PD_ODE_DAMPING_RATIO of critical, kd = 2 zeta sqrt(kp m). ODE's spring
 * form for a step h: erp = h kp / (h kp + kd), cfm = 1 / (h kp + kd). */
static void contact_softness(pd_engine_world *w, const pd_body *body, double g)
{
    double kp = body->mass * g / (PD_ODE_SINK_REL * body->size);
    double kd = 2.0 * PD_ODE_DAMPING_RATIO * sqrt(kp * body->mass);
    double h = w->dt;
    w->erp = h * kp / (h * kp + kd);
    w->cfm = 1.0 / (h * kp + kd);
}

static pd_engine_world *world_alloc(const pd_body *body, const pd_hull *hull,
                                    const pd_scene *scene, double dt)
{
    if (!body || !hull || !scene || !(dt > 0.0) || !isfinite(dt) || hull->nverts != body->nverts ||
        hull->nfacets < 4)
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
    w->dt = dt;
    w->mu = scene->mu;
    w->restitution = scene->restitution;
    double g = scale_gravity(scene);
    w->bounce_vel = PD_ODE_BOUNCE_VEL_REL * sqrt(g * body->size);
    contact_softness(w, body, g);
    if (!build_convex(w, body, hull))
        goto fail;
    w->world = dWorldCreate();
    w->space = w->world ? dSimpleSpaceCreate(0) : NULL;
    w->contacts = w->space ? dJointGroupCreate(0) : NULL;
    /* Without one of its own, a world steps on ODE's process-wide default
     * threading object, whose fake locks assert when two threads step at
     * once (measured: "assertion failed in WaitWakeup"). One self-threaded
     * implementation per world keeps the worlds independent. */
    w->threading = w->contacts ? dThreadingAllocateSelfThreadedImplementation() : NULL;
    if (!w->threading)
        goto fail;
    dWorldSetStepThreadingImplementation(w->world, dThreadingImplementationGetFunctions(w->threading),
                                         w->threading);
    dWorldSetGravity(w->world, 0.0, 0.0, -scene->gravity);
    /* The contacts carry their own erp/cfm; these only matter if a joint
     * without them were ever added. */
    dWorldSetERP(w->world, w->erp);
    dWorldSetCFM(w->world, w->cfm);
    /* A surface layer would let the part rest that far inside the floor;
     * heights must be the facet's. */
    dWorldSetContactSurfaceLayer(w->world, 0.0);

    w->body = dBodyCreate(w->world);
    if (!w->body)
        goto fail;
    dMass m;
    dMassSetParameters(&m, body->mass, 0.0, 0.0, 0.0, body->moment[0], body->moment[1],
                       body->moment[2], 0.0, 0.0, 0.0);
    dBodySetMass(w->body, &m);
    /* The exact rotation for the step's angular velocity instead of the
     * first-order quaternion update: a tumbling part keeps its unit norm
     * without renormalisation drift, and free flight is closer to Euler's
     * equations. */
    dBodySetFiniteRotationMode(w->body, 1);
    dBodySetAutoDisableFlag(w->body, 0);

    w->convex = dCreateConvex(w->space, w->planes, (unsigned int)hull->nfacets, w->points,
                              (unsigned int)body->nverts, w->polygons);
    w->plane = w->convex ? dCreatePlane(w->space, 0.0, 0.0, 1.0, 0.0) : NULL;
    if (!w->plane)
        goto fail;
    dGeomSetBody(w->convex, w->body);
    return w;
fail:
    world_free(w);
    return NULL;
}

static int state_finite(const pd_state *s)
{
    return v3_isfinite(s->x) && v3_isfinite(s->v) && v3_isfinite(s->w) && isfinite(s->q.w) &&
           isfinite(s->q.x) && isfinite(s->q.y) && isfinite(s->q.z);
}

static pd_status reset(pd_engine_world *w, const pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    if (!state_finite(s))
        return PD_ERR_NONFINITE;
    dJointGroupEmpty(w->contacts);
    dBodySetPosition(w->body, s->x.x, s->x.y, s->x.z);
    dQuaternion q = {s->q.w, s->q.x, s->q.y, s->q.z};
    dBodySetQuaternion(w->body, q);
    dBodySetLinearVel(w->body, s->v.x, s->v.y, s->v.z);
    /* ODE's angular velocity is in the world frame, pd_state's in the body's. */
    pd_vec3 ww = quat_rotate(s->q, s->w);
    dBodySetAngularVel(w->body, ww.x, ww.y, ww.z);
    dBodySetForce(w->body, 0.0, 0.0, 0.0);
    dBodySetTorque(w->body, 0.0, 0.0, 0.0);
    dBodyEnable(w->body);
    return PD_OK;
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
static int select_contacts(dContactGeom *c, int n)
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
    double mind[ODE_CANDIDATES];
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

static pd_status step(pd_engine_world *w, pd_state *s)
{
    if (!w || !s)
        return PD_ERR_USAGE;
    dContactGeom cg[ODE_CANDIDATES];
    int n = dCollide(w->convex, w->plane, ODE_CANDIDATES, cg, (int)sizeof cg[0]);
    n = select_contacts(cg, n);
    for (int i = 0; i < n; i++) {
        dContact c;
        memset(&c, 0, sizeof c);
        c.geom = cg[i];
        c.surface.mode = dContactApprox1 | dContactBounce | dContactSoftERP | dContactSoftCFM;
        c.surface.mu = w->mu;
        c.surface.bounce = w->restitution;
        c.surface.bounce_vel = w->bounce_vel;
        c.surface.soft_erp = w->erp;
        c.surface.soft_cfm = w->cfm;
        /* Friction pyramid's first axis along the slip (see the top). The
         * contact normal points from the floor into the part (geom order
         * convex, plane gives the plane's normal, +z). */
        dVector3 pv;
        dBodyGetPointVel(w->body, cg[i].pos[0], cg[i].pos[1], cg[i].pos[2], pv);
        double tx = pv[0], ty = pv[1];
        double ts = sqrt(tx * tx + ty * ty);
        if (ts > 0.0) {
            c.surface.mode |= dContactFDir1;
            c.fdir1[0] = tx / ts;
            c.fdir1[1] = ty / ts;
            c.fdir1[2] = 0.0;
        }
        dJointID j = dJointCreateContact(w->world, w->contacts, &c);
        if (!j) {
            dJointGroupEmpty(w->contacts);
            return PD_ERR_NOMEM;
        }
        dJointAttach(j, w->body, NULL);
    }
    int ok = dWorldStep(w->world, w->dt);
    dJointGroupEmpty(w->contacts);
    if (!ok)
        return PD_ERR_NOMEM;

    const dReal *x = dBodyGetPosition(w->body);
    const dReal *q = dBodyGetQuaternion(w->body);
    const dReal *v = dBodyGetLinearVel(w->body);
    const dReal *av = dBodyGetAngularVel(w->body);
    pd_state r;
    r.x = v3(x[0], x[1], x[2]);
    r.q = quat(q[0], q[1], q[2], q[3]);
    r.v = v3(v[0], v[1], v[2]);
    r.w = quat_rotate_inv(r.q, v3(av[0], av[1], av[2]));
    if (!state_finite(&r))
        return PD_ERR_NONFINITE;
    *s = r;
    return PD_OK;
}

const pd_engine pd_engine_ode = {"ode", world_alloc, world_free, reset, step};
