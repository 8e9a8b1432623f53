/* contact_time.c: the time of a flight's next contact with the floor (see flight.h).
 *
 * Conservative advancement (Mirtich, "Impulse-based dynamic simulation of
 * rigid body systems", PhD thesis, Berkeley 1996, ch. 2; our formulation).
 * The support height s(t) = min over hull vertices of their world z can fall
 * no faster than the com's descent plus the fastest vertex speed about it:
 *   -ds/dt <= max(0, -vz(t)) + wmax rmax,    vz(t) = vz(t0) - g (t - t0),
 * so from a sample at t0 with gap s0 > 0 the gap stays positive for
 *   c D + g D^2 / 2 + W D < s0,  c = max(0, -vz(t0)), W = wmax rmax.
 * Stepping by the root D of that quadratic never passes the first contact, so
 * no contact is missed however briefly it dips below the floor, and the
 * iterates approach the first contact from above. Each step closes at least
 * the fraction (true approach speed)/(bound) of the gap; a straight fall lands
 * in one step.
 *
 * For hulls of up to VERTEX_BOUND_MAX vertices a second, per-vertex bound is
 * taken too, and the larger step of the two: each vertex height z_v(t) has
 * the exact rate z_v' at the sample and a second derivative no lower than
 * -B, B = g + 2 wmax^2 rmax (centripetal wmax^2 r, and |dw/dt| <= Jmax |L|
 * |w| <= wmax^2 for torque-free motion), so z_v stays positive while
 * z_v + z_v' D - B D^2 / 2 > 0. Its smallest root over the vertices is a
 * step that cannot pass a contact either, and, being exact to first order,
 * it lands a vertex approaching at any speed in a step or two, where the
 * worst-case speed bound creeps up on a spinning part in tens. */
#include <math.h>
#include "flight.h"
#include "posedrop/tolerances.h"
#include "vec3.h"

/* Support height of state s: the lowest vertex (hill-climbed from *hint)
 * and its z. */
static pd_status support_of(const pd_body *b, const pd_state *s, int *hint, double *height)
{
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    *hint = pd_body_support(b, up, *hint);
    *height = s->x.z + v3_dot(up, b->verts[*hint]);
    if (!isfinite(*height))
        return PD_ERR_NONFINITE;
    return PD_OK;
}

/* The same at time t of the flight, s receiving the state there. */
static pd_status support_at(const pd_body *b, const pd_flight *f, double t, pd_state *s,
                            int *hint, double *height)
{
    pd_status st = pd_flight_eval(f, t, s);
    return st != PD_OK ? st : support_of(b, s, hint, height);
}

/* Per-vertex bound: above this many vertices the scan costs more than the
 * evaluations it saves, and the speed bound alone is used. */
enum { VERTEX_BOUND_MAX = 512 };

/* The per-vertex step from state s (header): the smallest positive root of
 * z_v + z_v' D - B D^2 / 2 over the vertices, z_v > 0 for all of them. A
 * vertex whose quadratic is still positive at the best step so far cannot
 * have a smaller root (the quadratic is concave and positive at 0): skipped
 * without a square root. */
static double vertex_step(const pd_body *b, const pd_state *s, double B, int lowest)
{
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    pd_vec3 a = v3_cross(up, s->w); /* z_v' = v_z + b_v . (up x w), body frame */
    double best = HUGE_VAL;
    for (int k = -1; k < b->nverts; k++) {
        int v = k < 0 ? lowest : k;
        if (k == lowest)
            continue;
        double z = s->x.z + v3_dot(up, b->verts[v]);
        double dz = s->v.z + v3_dot(a, b->verts[v]);
        if (best < HUGE_VAL && z + best * (dz - 0.5 * B * best) > 0.0)
            continue;
        double root = 2.0 * z / (-dz + sqrt(dz * dz + 2.0 * B * z));
        if (root < best)
            best = root;
    }
    return best > 0.0 ? best : 0.0;
}

/* The contact set: vertices within tol of the floor, or that would reach it
 * within window (s) at their present velocity (a vertex's extrapolated
 * height z + z' window). Found by breadth-first search from the lowest one
 * over the edge graph: the vertices of a convex polytope below a plane form
 * a connected subgraph, and so do those of its image under the rigid motion
 * extrapolated linearly (an affine map, which keeps the polytope's edges);
 * both sets hold the lowest vertex, which is approaching, so their union is
 * connected too and the search finds it all while visiting only it and its
 * neighbours. The list doubles as the queue; membership is a linear search,
 * cheap because contact sets are small (a face's corners). Beyond ncap the
 * set is counted, not listed. */
static int contact_set(const pd_body *b, const pd_state *s, int lowest, double tol, double window,
                       int *list, int ncap)
{
    pd_vec3 up = quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0));
    pd_vec3 a = v3_cross(up, s->w); /* z_v' = v_z + b_v . (up x w), body frame */
    if (ncap < 1 || !list)
        return 1;
    int n = 0;
    list[n++] = lowest;
    for (int head = 0; head < n; head++) {
        int v = list[head];
        for (int k = b->adj_start[v]; k < b->adj_start[v + 1]; k++) {
            int w = b->adj[k];
            double z = s->x.z + v3_dot(up, b->verts[w]);
            double zw = z + window * (s->v.z + v3_dot(a, b->verts[w]));
            if (z > tol && zw > tol)
                continue;
            int seen = 0;
            for (int i = 0; i < n && !seen; i++)
                seen = list[i] == w;
            if (seen)
                continue;
            if (n == ncap)
                return n + 1; /* at least one more than listed */
            list[n++] = w;
        }
    }
    return n;
}

pd_status pd_flight_impact(const pd_body *b, const pd_flight *f, double t_max, double window,
                           int *contacts, int ncap, pd_impact *out)
{
    if (!f)
        return PD_ERR_USAGE;
    return pd_flight_impact_from(b, f, 0.0, &f->s0, t_max, window, contacts, ncap, out);
}

pd_status pd_flight_impact_from(const pd_body *b, const pd_flight *f, double t0, const pd_state *at,
                                double t_max, double window, int *contacts, int ncap, pd_impact *out)
{
    if (!b || !f || !at || !out || !(t0 >= 0.0) || !(t_max >= t0) || !(window >= 0.0) || ncap < 0 ||
        (ncap > 0 && !contacts))
        return PD_ERR_USAGE;
    double tol = PD_TOL_IMPACT_REL * b->size;
    double W = f->wmax * b->rmax;
    double B = f->g + 2.0 * f->wmax * f->wmax * b->rmax;
    pd_impact r = {PD_IMPACT_NONE, 0.0, 0, 0.0, 0, 0};
    pd_state s = *at;
    int hint = 0;
    double t = t0, h;
    /* Start from the body's lowest vertex in the initial orientation: the scan
     * is avoided by hill-climbing from vertex 0. */
    pd_status st = support_of(b, &s, &hint, &h);
    if (st != PD_OK)
        return st;
    if (h <= tol) {
        r.kind = PD_IMPACT_NOW;
    } else {
        for (;;) {
            if (r.steps++ >= PD_CONTACT_MAX_STEPS)
                return PD_ERR_NO_CONVERGENCE;
            double vz = f->s0.v.z - f->g * t;
            double c = (vz < 0.0 ? -vz : 0.0) + W;
            /* Root of g/2 D^2 + c D = h in the form without cancellation. */
            double disc = c * c + 2.0 * f->g * h;
            double D = disc > 0.0 ? 2.0 * h / (c + sqrt(disc)) : HUGE_VAL;
            if (b->nverts <= VERTEX_BOUND_MAX) {
                double Dv = vertex_step(b, &s, B, hint);
                if (Dv > D)
                    D = Dv;
            }
            if (t + D >= t_max) {
                /* The bound keeps the gap open up to t_max, but the last
                 * sample may still close it: look at t_max itself. */
                double hm;
                int hm_hint = hint;
                pd_state sm;
                if ((st = support_at(b, f, t_max, &sm, &hm_hint, &hm)) != PD_OK)
                    return st;
                if (hm > tol) {
                    r.t = t_max;
                    r.vertex = hm_hint;
                    r.height = hm;
                    *out = r;
                    return PD_OK;
                }
                t = t_max; /* touching at t_max itself, within the tolerance */
                s = sm;
                hint = hm_hint;
                h = hm;
                break;
            }
            t += D;
            if ((st = support_at(b, f, t, &s, &hint, &h)) != PD_OK)
                return st;
            if (h <= tol)
                break;
        }
        r.kind = PD_IMPACT_AT;
    }
    r.t = t;
    r.vertex = hint;
    r.height = h;
    r.ncontacts = contact_set(b, &s, hint, PD_TOL_CONTACT_REL * b->size, window, contacts, ncap);
    *out = r;
    return PD_OK;
}
