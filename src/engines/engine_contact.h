/* engine_contact.h (private): the spring-dashpot that stands for the
 * scene's contact in the stepping engines. Inline in a header because the
 * engines live in two libraries (ODE in libposedrop, Bullet in
 * libposedrop-bullet), and this is no part of libposedrop's interface. */
#ifndef PD_ENGINE_CONTACT_H
#define PD_ENGINE_CONTACT_H

#include <math.h>
#include "posedrop/hull.h"
#include "posedrop/sim.h"
#include "engines/engines_tol.h"

/* Restitution below this is taken as this by the contact law below, as by
 * the impulse simulator's compliant law (PD_COMPLIANT_E_MIN, in a layer this
 * one may not include): e = 0 needs an infinite damping ratio. */
#define PD_ENGINE_E_MIN 0.01

/* Steps a contact must span for an engine to stand for it by that law: with
 * a step h > T / PD_ENGINE_CONTACT_STEPS the engine keeps its own contact
 * (its bounce with restitution e), the law's own limit as T -> 0. Why 10:
 * the engines step the law as semi-implicit Euler (PD_ENGINE_SPRING_IMPLICIT
 * in engines_tol.h), whose rebound wavers with where in its step a vertex
 * touches: within 0.007 of e at 10 steps a contact, 0.03 at 5 and 0.24 at
 * 2.5 (the scaled law stepped so, e 0.05 to 1,
 * scripts/engine-step-rebound.py); and the several vertices
 * of a face press at a higher rate than one, which the step must still
 * resolve. A contact that short is rigid as far as such a step can tell. */
#define PD_ENGINE_CONTACT_STEPS 10.0

/* Depth a contact may reach at the fall speed, times the part's thickness,
 * for an engine to stand for the scene's contact by that law. The engines
 * meet the floor at the hull's vertices only, so a penetration of the order
 * of the thickness puts corners of the far side below the floor, and the
 * part rests part way through it (measured: a 1 m x 3.3 mm rod at a
 * contact time of 29 to 30 ms, omega ~ 90 rad/s, resolved by ODE's 1 ms
 * step, came to rest 2.6 mm deep on an edge in 3 of 100 drops). The
 * spring-dashpot's deepest point at approach speed v is below v / omega (its
 * undamped amplitude); with v / omega above this share of the thickness the
 * engine keeps its own contact, as for a contact the step cannot resolve.
 * Why 0.1: a corner then stays within a tenth of the thickness of the
 * floor, so no far corner comes near it whatever the orientation. Parts of
 * centimetres never meet it at the default steps: their automatic contact
 * (0.5 ms for a 1 cm cube) is not resolved by a 1 ms step in the first
 * place. */
#define PD_ENGINE_CONTACT_DEPTH_REL 0.1

/* The part's thickness: its least width across a facet's plane (m, part
 * frame or any: a width does not depend on it). A convex body's least width
 * is across a facet or between two edges; the least facet width is that
 * or more (equal for boxes, prisms and flat pyramids, the parts whose
 * thinness matters here). */
static inline double pd_engine_hull_width(const pd_hull *h)
{
    double width = INFINITY;
    for (int f = 0; f < h->nfacets; f++) {
        double lo = h->offset[f];
        for (int i = 0; i < h->nverts; i++) {
            double d = h->normal[f].x * h->verts[i].x + h->normal[f].y * h->verts[i].y +
                       h->normal[f].z * h->verts[i].z;
            lo = fmin(lo, d);
        }
        width = fmin(width, h->offset[f] - lo);
    }
    return width;
}

/* The fastest a corner meets the floor (m/s) in a drop of scene for a part
 * of size L: a fall from the drop height (the top of its range) plus its own
 * size, as a tumbling part's corner can come down that much further. */
static inline double pd_engine_fall_speed(const pd_scene *scene, double size)
{
    const pd_dist *h = &scene->range[PD_PARAM_HEIGHT];
    double height = h->kind == PD_DIST_FIXED ? scene->height : h->hi;
    return sqrt(2.0 * fabs(scene->gravity) * (height + size));
}

/* Whether an engine stepping dt stands for the scene's contact by the law
 * below: the contact is soft (contact_time > 0), the step resolves it
 * (PD_ENGINE_CONTACT_STEPS) and its depth at fall speed v stays within
 * PD_ENGINE_CONTACT_DEPTH_REL of the thickness (omega from the law). */
static inline int pd_engine_contact_resolved(double dt, double contact_time, double omega,
                                             double v, double width)
{
    return contact_time > 0.0 && dt * PD_ENGINE_CONTACT_STEPS <= contact_time &&
           v <= PD_ENGINE_CONTACT_DEPTH_REL * width * omega;
}

/* Steps per contact of the automatic step (dt auto): the lowest contact
 * time the scene can draw, T, is cut into this many steps, so that every
 * contact is the scene's law (at least PD_ENGINE_CONTACT_STEPS steps) and
 * its rebound is within 0.0016 of e wherever the vertex touches in its step
 * (engines_tol.h, PD_ENGINE_SPRING_IMPLICIT). Why 20: the coarsest of 10,
 * 20 and 40 at which halving the step moved no pose class of the
 * cross-check corpus's parts measured beyond sampling noise, on either
 * engine (docs/engines-crosscheck.md, "Converged by default",
 * scripts/engine-convergence.py). */
#define PD_ENGINE_AUTO_STEPS 20.0

/* The most a corner may travel in one automatic step at the fall speed,
 * times the part's thickness: a rigid scene (contact time 0) has no
 * contact to resolve, and this bounds its step by the motion instead, so
 * that no step lets a corner pass a tenth of the part's thickness before
 * its contact is found (0.6 ms for a 1 cm cube dropped 12 cm). Parts of
 * centimetres with a soft contact never meet it: their contact is shorter. */
#define PD_ENGINE_AUTO_TRAVEL_REL 0.1

/* The automatic step (s) of a stepping engine for a scene whose contacts
 * last at least contact_time (0: rigid), whose corners meet the floor at
 * up to speed v, for a part of thickness width: PD_ENGINE_AUTO_STEPS steps
 * per contact, and no more than PD_ENGINE_AUTO_TRAVEL_REL of the thickness
 * travelled per step; at most dt_max. */
static inline double pd_engine_dt_auto(double contact_time, double v, double width, double dt_max)
{
    double dt = dt_max;
    if (contact_time > 0.0)
        dt = fmin(dt, contact_time / PD_ENGINE_AUTO_STEPS);
    if (v > 0.0 && width > 0.0)
        dt = fmin(dt, PD_ENGINE_AUTO_TRAVEL_REL * width / v);
    return dt;
}

/* Bisection halvings of zeta's bracket: 200 reach round-off of any bracket. */
enum { PD_ENGINE_CONTACT_HALVINGS = 200 };

/* The bracket's top: e(zeta) ~ 1 / (2 zeta)^2 for large zeta, 2.5e-7 at
 * 1000, far below PD_ENGINE_E_MIN. */
#define PD_ENGINE_CONTACT_ZETA_MAX 1000.0

/* Duration of a push-only contact times omega (pd_engine_contact_law). */
static inline double pd_engine_contact_duration(double zeta)
{
    const double pi = 3.14159265358979323846;
    if (zeta < 1.0)
        return (pi - 2.0 * asin(zeta)) / sqrt(1.0 - zeta * zeta);
    if (zeta > 1.0)
        return 2.0 * acosh(zeta) / sqrt(zeta * zeta - 1.0);
    return 2.0;
}

static inline double pd_engine_contact_restitution(double zeta)
{
    return exp(-zeta * pd_engine_contact_duration(zeta));
}

/* The linear spring-dashpot fitted to one contact of the scene (contact_time
 * T > 0, restitution e), as natural frequency *omega (rad/s) and damping
 * ratio *zeta, for a contact of effective mass m: stiffness k = m omega^2,
 * damping c = 2 zeta m omega. The contact pushes only (the engines' contact
 * impulses are never negative), so it ends when the force k x + c x' falls
 * to zero, before the penetration does; for that law
 *     T = g(zeta) / omega,   e = exp(-zeta g(zeta)),
 *     g(zeta) = (pi - 2 asin zeta) / sqrt(1 - zeta^2)     (zeta < 1),
 *             = 2 acosh(zeta) / sqrt(zeta^2 - 1)          (zeta > 1), 2 at 1,
 * whatever the approach speed. zeta is found from e by bisection (e falls
 * from 1 at zeta = 0 toward 0), then omega from T. e is taken within
 * [PD_ENGINE_E_MIN, 1]. docs/engines-crosscheck.md derives it. Not the
 * engines' contact law (points sharing one contact under it land stiffer
 * and more damped than one contact: pd_engine_hc_law says why); its omega
 * sets their drilling patch, the sink under the weight g / omega^2
 * (drilling_arm in engine_ode.c says why). */
static inline void pd_engine_contact_law(double T, double e, double *omega, double *zeta)
{
    double target = fmin(1.0, fmax(e, PD_ENGINE_E_MIN));
    double lo = 0.0, hi = PD_ENGINE_CONTACT_ZETA_MAX;
    for (int i = 0; i < PD_ENGINE_CONTACT_HALVINGS && lo < hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (pd_engine_contact_restitution(mid) > target)
            lo = mid;
        else
            hi = mid;
    }
    *zeta = target >= 1.0 ? 0.0 : 0.5 * (lo + hi);
    *omega = pd_engine_contact_duration(*zeta) / T;
}

/* The impulse simulator's contact law, which the stepping engines realise
 * (compliant.c; docs/contact.md): each vertex below the floor pushes with
 * the Hunt-Crossley force F = k d (1 + lambda d'), d its depth and d' the
 * rate, k = m_eff omega^2 for its own effective mass along
 * the normal and lambda = chi / v0, v0 its approach speed when it touched.
 * Scaled (time by 1 / omega, depth by v0 / omega) the contact is
 * s'' = -s (1 + chi s'), started at s = 0, s' = 1, whatever the mass and the
 * speed; so its rebound and its duration do not depend on the stiffness:
 * vertices that land together (a face, an edge) rebound together with e,
 * however many there are, where a linear dashpot fitted to each vertex's
 * own mass made their sum stiffer and more damped than the law
 * (docs/engines-crosscheck.md). The rebound has a closed form:
 * along the contact s'/chi - ln(1 + chi s')/chi^2 + s^2/2 is constant, so
 * at its end (s = 0, s' = -e)
 *     ln((1 + chi) / (1 - chi e)) = chi (1 + e),
 * whose root in (0, 1/e) is chi (bisection: the left side less the right
 * is negative from 0 to the root, positive after it); chi = 0 at e = 1. Its
 * duration tau (scaled time) is integrated by classical RK4 in steps of
 * pi / PD_ENGINE_HC_STEPS, the end located within the last step on the
 * cubic through both ends' s and s' (PD_ENGINE_HC_STEPS says why that is
 * within 1e-8 of tau); omega = tau / T. */
static inline double pd_engine_hc_gap(double chi, double e)
{
    return log((1.0 + chi) / (1.0 - chi * e)) - chi * (1.0 + e);
}

static inline void pd_engine_hc_accel(double chi, double s, double v, double *a)
{
    double f = s * (1.0 + chi * v);
    *a = f > 0.0 ? -f : 0.0;
}

/* The root in (0, 1] of the cubic Hermite interpolant through (0, s0, v0 h)
 * and (1, s1, v1 h), s0 > 0 >= s1: where a step of h ends the contact. */
static inline double pd_engine_hc_crossing(double s0, double v0, double s1, double v1, double h)
{
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < PD_ENGINE_CONTACT_HALVINGS; i++) {
        double x = 0.5 * (lo + hi);
        if (x <= lo || x >= hi)
            break;
        double x2 = x * x, x3 = x2 * x;
        double p = (2.0 * x3 - 3.0 * x2 + 1.0) * s0 + (x3 - 2.0 * x2 + x) * h * v0 +
                   (3.0 * x2 - 2.0 * x3) * s1 + (x3 - x2) * h * v1;
        if (p > 0.0)
            lo = x;
        else
            hi = x;
    }
    return 0.5 * (lo + hi);
}

static inline void pd_engine_hc_law(double T, double e, double *omega, double *chi)
{
    const double pi = 3.14159265358979323846;
    double target = fmin(1.0, fmax(e, PD_ENGINE_E_MIN));
    double c = 0.0;
    if (target < 1.0) {
        double lo = 0.0, hi = 1.0 / target;
        for (int i = 0; i < PD_ENGINE_CONTACT_HALVINGS; i++) {
            double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi)
                break;
            if (pd_engine_hc_gap(mid, target) < 0.0)
                lo = mid;
            else
                hi = mid;
        }
        c = 0.5 * (lo + hi);
    }
    double h = pi / PD_ENGINE_HC_STEPS, t = 0.0, s = 0.0, v = 1.0, tau = 0.0;
    for (long k = 0; k < (long)PD_ENGINE_HC_HALF_PERIODS * PD_ENGINE_HC_STEPS; k++) {
        double a1, a2, a3, a4;
        pd_engine_hc_accel(c, s, v, &a1);
        pd_engine_hc_accel(c, s + 0.5 * h * v, v + 0.5 * h * a1, &a2);
        pd_engine_hc_accel(c, s + 0.5 * h * (v + 0.5 * h * a1), v + 0.5 * h * a2, &a3);
        pd_engine_hc_accel(c, s + h * (v + 0.5 * h * a2), v + h * a3, &a4);
        double s1 = s + h * (v + h * (a1 + a2 + a3) / 6.0);
        double v1 = v + h * (a1 + 2.0 * a2 + 2.0 * a3 + a4) / 6.0;
        if (s1 <= 0.0 && v1 < 0.0) {
            tau = t + h * pd_engine_hc_crossing(s, v, s1, v1, h);
            break;
        }
        t += h;
        s = s1;
        v = v1;
        tau = t;
    }
    *chi = c;
    *omega = tau / T;
}

#endif
