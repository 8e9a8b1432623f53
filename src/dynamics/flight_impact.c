/* flight_impact.c: the time of a flight's next contact with the floor (see flight.h).
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
 * A second, per-vertex bound is taken too, and the larger step of the two:
 * each vertex height z_v(t) has the exact rate z_v' at the sample and a
 * second derivative no lower than -B, B = g + (1 + k) wmax^2 rmax
 * (centripetal wmax^2 r, and |dw/dt| <= k |w|^2 for torque-free motion,
 * k = spin_accel from Euler's equations, at most 1/sqrt(3)), so z_v stays
 * positive while z_v + z_v' D - B D^2 / 2 > 0. Its smallest root over the vertices is a
 * step that cannot pass a contact either, and, being exact to first order,
 * it lands a vertex approaching at any speed in a step or two, where the
 * worst-case speed bound creeps up on a spinning part in tens. That smallest
 * root is found by hill-climbing the hull, not by visiting every vertex:
 * lowest_root.
 *
 * From a search's second step on, the per-vertex bound takes each vertex's
 * exact second derivative at the sample instead of B, and bounds the third.
 * With up' = up x w =: a and up'' = a x w + up x dw/dt =: c, so
 * |c| <= (1 + k) |w|^2, and up''' = up'' x w + 2 up' x dw/dt + up x d2w/dt2:
 * differentiating Euler's equations, dw_i/dt = a_i w_j w_k with every |a_i|
 * at most sqrt(3) k, gives d2w_i/dt2 = a_i w_i (a_j w_k^2 + a_k w_j^2), so
 * |d2w/dt2| <= 3 k^2 |w|^3 and |up'''| <= (1 + 3k + 3k^2) |w|^3. Hence
 * z_v'' = -g + b_v . c exactly and |z_v'''| <= C = (1 + 3k + 3k^2) wmax^3
 * rmax, and by Taylor's theorem, for 0 <= D <= H,
 *   z_v(t0 + D) >= z_v + z_v' D + z_v'' D^2 / 2 - C D^3 / 6
 *               >= z_v + z_v' D - (B0 - b_v . c) D^2 / 2,
 *   B0 = max(g + C H / 3, |c| rmax),
 * the max making every vertex's quadratic concave (b_v . c <= |c| rmax)
 * while it stays a lower bound. As B0 - b_v . c is linear in b_v, the vertex
 * whose quadratic is lowest at D is the support vertex in direction
 * up + D a + D^2 c / 2, and the same search (lowest_root) applies, run on each root
 * capped at H (where the bound ends): a vertex lowest at H whose quadratic is
 * not below 0 there leaves no root before H. The result is a step that
 * cannot pass a contact. Exact to second order, it closes the gap near
 * contact in fewer steps: what it leaves is at most C D^3 / 6, where the
 * first bound leaves up to (B + z_v'') D^2 / 2. H is twice the search's
 * previous step (steps shrink as the gap closes, and one that does not may
 * double), so the first step, with no previous one, keeps B. */
#include <math.h>
#include "dynamics/flight.h"
#include "posedrop/tolerances.h"
#include "dynamics/dynamics_tol.h"
#include "base/vec3.h"

/* A sample of the flight: the state, world up in the body frame, and the
 * lowest vertex with its height. */
typedef struct sample {
    pd_state s;
    pd_vec3 up;
    int low;
    double h;
} sample;

/* Fills in p's up, lowest vertex (hill-climbed from p->low) and height from
 * its state. */
static pd_status lowest_of(const pd_body *b, sample *p)
{
    p->up = quat_rotate_inv(p->s.q, v3(0.0, 0.0, 1.0));
    p->low = pd_body_support(b, p->up, p->low);
    p->h = p->s.x.z + v3_dot(p->up, b->verts[p->low]);
    return isfinite(p->h) ? PD_OK : PD_ERR_NONFINITE;
}

/* The same at time t of the flight. */
static pd_status sample_at(const pd_body *b, const pd_flight *f, double t, sample *p)
{
    pd_status st = pd_flight_eval(f, t, &p->s);
    return st != PD_OK ? st : lowest_of(b, p);
}

/* Vertex v's root of z_v + z_v' D - B D^2 / 2 in state s (up: world up in
 * the body frame, a = up x w), in the form without cancellation; infinite
 * when it has none (B = 0 and v not approaching). */
static double vertex_root(const pd_body *b, const pd_state *s, pd_vec3 up, pd_vec3 a, double B,
                          int v)
{
    double z = s->x.z + v3_dot(up, b->verts[v]);
    double dz = s->v.z + v3_dot(a, b->verts[v]); /* z_v' = v_z + b_v . (up x w) */
    return 2.0 * z / (-dz + sqrt(dz * dz + 2.0 * B * z));
}

/* Vertex v's root of z_v + z_v' D - (B0 - b_v . c) D^2 / 2, the coefficient
 * kept from going below 0 by the round-off of B0's bound. */
static double curvature_root(const pd_body *b, const pd_state *s, pd_vec3 up, pd_vec3 a,
                             pd_vec3 c, double B0, int v)
{
    double Bv = B0 - v3_dot(c, b->verts[v]);
    return vertex_root(b, s, up, a, Bv > 0.0 ? Bv : 0.0, v);
}

/* The smallest root, capped at H, over the vertices of z_v + z_v' D -
 * (B0 - b_v . c) D^2 / 2, without visiting every vertex. Vertex v's
 * quadratic is below 0 at D exactly when (up + D a + D^2 c / 2) . b_v <
 * B0 D^2 / 2 - z - v_z D (b_v: v in the body frame), so the vertex whose
 * quadratic is lowest at D is the support vertex in that direction. From any
 * vertex's root D, which is >= D* (the smallest), the support vertex w there
 * either is the vertex whose root D is (then every quadratic is >= 0 at D:
 * they are concave and positive at 0, so no root is below D, and D = D*) or
 * has a quadratic below 0 at D, hence a smaller root, which the search moves
 * to. D falls strictly, so no vertex comes twice; in practice one or two
 * moves, each a short hill-climb from the last vertex. With no root (c = 0,
 * B0 = 0: no spin, no gravity; H infinite) the direction is a alone, the
 * limit. */
static double lowest_root(const pd_body *b, const pd_state *s, pd_vec3 up, pd_vec3 a, pd_vec3 c,
                          double B0, double H, int start)
{
    int v = start;
    double D = curvature_root(b, s, up, a, c, B0, v);
    D = D < H ? D : H;
    for (;;) {
        pd_vec3 dir = D < HUGE_VAL ? v3_add(up, v3_scale(v3_add(a, v3_scale(c, 0.5 * D)), D)) : a;
        int w = pd_body_support(b, dir, v);
        double Dw = w == v ? D : curvature_root(b, s, up, a, c, B0, w);
        Dw = Dw < H ? Dw : H;
        if (!(Dw < D)) /* w == v, or a tie within round-off */
            break;
        v = w;
        D = Dw;
    }
    return D > 0.0 ? D : 0.0;
}

/* The per-vertex step (header, flight.h): every vertex's curvature bounded
 * by the same B. */
static double vertex_step(const pd_body *b, const pd_state *s, pd_vec3 up, double B, int start)
{
    return lowest_root(b, s, up, v3_cross(up, s->w), v3(0.0, 0.0, 0.0), B, HUGE_VAL, start);
}

/* The curvature step (header): each vertex's own curvature, capped at H;
 * b->euler gives dw_i/dt = euler_i w_j w_k. */
static double curvature_step(const pd_body *b, const pd_state *s, pd_vec3 up, double g, double C,
                             double H, int start)
{
    pd_vec3 w = s->w, a = v3_cross(up, w);
    const double *e = b->euler;
    pd_vec3 dw = v3(e[0] * w.y * w.z, e[1] * w.z * w.x, e[2] * w.x * w.y);
    pd_vec3 c = v3_add(v3_cross(a, w), v3_cross(up, dw));
    double B0 = g + C * H / 3.0, Bc = v3_norm(c) * b->rmax;
    return lowest_root(b, s, up, a, c, Bc > B0 ? Bc : B0, H, start);
}

double pd_flight_vertex_step(const pd_body *b, const pd_state *s, double B, int start)
{
    return vertex_step(b, s, quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0)), B, start);
}

/* The bound C on every vertex's third derivative (header). */
static double third_bound(const pd_body *b, double wmax)
{
    double k = b->spin_accel;
    return (1.0 + 3.0 * k + 3.0 * k * k) * wmax * wmax * wmax * b->rmax;
}

double pd_flight_curvature_step(const pd_body *b, const pd_state *s, double g, double wmax,
                                double H, int start)
{
    return curvature_step(b, s, quat_rotate_inv(s->q, v3(0.0, 0.0, 1.0)), g, third_bound(b, wmax), H,
                          start);
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
static int contact_set(const pd_body *b, const pd_state *s, pd_vec3 up, int lowest, double tol,
                       double window, int *list, int ncap)
{
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

pd_status pd_flight_impact(const pd_body *b, pd_flight *f, double t_max, double window,
                           int *contacts, int ncap, pd_impact *out)
{
    if (!f)
        return PD_ERR_USAGE;
    return pd_flight_impact_from(b, f, 0.0, &f->s0, 0, t_max, window, contacts, ncap, out);
}

pd_status pd_flight_impact_from(const pd_body *b, pd_flight *f, double t0, const pd_state *at,
                                int start, double t_max, double window, int *contacts, int ncap,
                                pd_impact *out)
{
    if (!b || !f || !at || !out || !(t0 >= 0.0) || !(t_max >= t0) || !(window >= 0.0) || ncap < 0 ||
        (ncap > 0 && !contacts))
        return PD_ERR_USAGE;
    double tol = PD_TOL_IMPACT_REL * b->size;
    double W = f->wmax * b->rmax;
    double B = f->g + (1.0 + b->spin_accel) * f->wmax * f->wmax * b->rmax;
    double C = third_bound(b, f->wmax);
    pd_impact r = {PD_IMPACT_NONE, 0.0, 0, 0.0, 0, 0};
    sample p = {*at, {0.0, 0.0, 0.0}, start, 0.0};
    double t = t0, D_last = 0.0; /* the search's last step, 0 before its first */
    pd_status st = lowest_of(b, &p);
    if (st != PD_OK)
        return st;
    if (p.h <= tol) {
        r.kind = PD_IMPACT_NOW;
    } else {
        if (f->kind == PD_FLIGHT_BOUNDS && (st = pd_flight_complete(b, f)) != PD_OK)
            return st;
        for (;;) {
            if (r.steps++ >= PD_CONTACT_MAX_STEPS)
                return PD_ERR_NO_CONVERGENCE;
            double vz = f->s0.v.z - f->g * t;
            double c = (vz < 0.0 ? -vz : 0.0) + W;
            /* Root of g/2 D^2 + c D = h in the form without cancellation. */
            double disc = c * c + 2.0 * f->g * p.h;
            double D = disc > 0.0 ? 2.0 * p.h / (c + sqrt(disc)) : HUGE_VAL;
            double Dv = D_last > 0.0 ? curvature_step(b, &p.s, p.up, f->g, C, 2.0 * D_last, p.low)
                                     : vertex_step(b, &p.s, p.up, B, p.low);
            if (Dv > D)
                D = Dv;
            D_last = D;
            if (t + D >= t_max) {
                /* The bound keeps the gap open up to t_max, but the last
                 * sample may still close it: look at t_max itself. */
                sample m = p;
                if ((st = sample_at(b, f, t_max, &m)) != PD_OK)
                    return st;
                if (m.h > tol) {
                    r.t = t_max;
                    r.vertex = m.low;
                    r.height = m.h;
                    *out = r;
                    return PD_OK;
                }
                t = t_max; /* touching at t_max itself, within the tolerance */
                p = m;
                break;
            }
            t += D;
            if ((st = sample_at(b, f, t, &p)) != PD_OK)
                return st;
            if (p.h <= tol)
                break;
        }
        r.kind = PD_IMPACT_AT;
    }
    r.t = t;
    r.vertex = p.low;
    r.height = p.h;
    r.ncontacts = contact_set(b, &p.s, p.up, p.low, PD_TOL_CONTACT_REL * b->size, window, contacts, ncap);
    *out = r;
    return PD_OK;
}
