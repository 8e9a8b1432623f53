/* descent_map.c: where quasi-static descent lands (pd_descend, topple.c),
 * looked up instead of walked.
 *
 * With gravity g in the normal cone of support vertex v, the walk pivots the
 * part about v: g moves on the great circle through g and u = v - com, away
 * from u, until it leaves the cone. The cone lies in the hemisphere u . g > 0
 * (the centre of mass is above v), where central projection from u makes it
 * a convex polygon and those circles rays from u's image. So every g on one
 * half circle from u leaves through the same point of the cone's far side,
 * and which arc of the far side it leaves through, hence the rest of the
 * walk, depends only on the azimuth of g about u. The far arcs are those of
 * the star edges (v, w) with lambda > 0 (pd_star_lambda: u is inside their
 * boundary plane); arc (v, w) between corners ca and cb (where its plane
 * meets its neighbours', next to the normals of the edge's two facets) takes
 * the g of the cone in the lune between the planes through u and ca and
 * through u and cb. When lambda < 1 the walk ends on that arc: the part rolls
 * about the edge away from its saddle s0 (the direction in which the centre
 * of mass stands over the edge, basin.c), to one facet from the exit points
 * on ca's side of s0 and to the other from those on cb's; the exit point is
 * on ca's side exactly when g is on ca's side of the plane through u and s0.
 * So such an arc answers one facet on either side of one plane, found once
 * here by the walk's own roll rule at a point of each side. Arcs past which
 * the part pivots on about w (lambda >= 1) are left to the walk, which is
 * rare in drops: of the 5538 lookups of the median drops of the cube, box
 * and coin, 2 walk (near a boundary); on the parts in parts/ up to 6% of
 * walks go on past a first pivot.
 *
 * A lookup climbs to v as pd_descend does, then answers only if g is inside
 * every boundary of v's cone and inside one mapped lune and one side of its
 * s0 plane, each by a margin; else it calls pd_descend. The exit point g1 is
 * farther from u than g on the same circle through u, and both are within
 * 90 degrees of u, so g1 is at least as far as g from any plane through u:
 * the margins hold for g1 too. They make every decision of the floating-point
 * walk the exact one, so the lookup is pd_descend's answer to the bit:
 *  - inside the cone by PD_TOL_DESCENT_MAP + PD_TOL_ANGLE (plus how far any
 *    facet normal of v lies inside its cone, fitted normals of merged facets
 *    being off their corners): the climb stops at v, no normal is within
 *    PD_TOL_ANGLE of g (pd_descend's test for resting on a facet already),
 *    and no boundary is taken for one g is on;
 *  - g1 at least PD_TOL_DESCENT_MAP from every other boundary plane of the
 *    cone, so the walk picks this arc: next to a corner that distance is
 *    sin(distance from the corner) sin(corner angle), so the margin is
 *    divided by the sine of the sharper corner; from the planes that meet
 *    neither corner the arc keeps at least its corners' distance (a sine
 *    curve, positive along the arc, is least at an end), asked to be that
 *    much here;
 *  - g1 farther than PD_TOL_ANGLE from the edge's facet normals (the margin
 *    includes their distance from the corners), so it does not snap to one;
 *    and farther than the margin from s0, so the roll rule picks this side.
 * Rounding moves each of these by ~1e-16 (for g1, relative to the margin
 * scaled the same way), so the margin keeps seven orders in hand. */
#include <math.h>
#include <stdlib.h>
#include "settle/descent_map.h"
#include "base/base_tol.h"
#include "settle/settle_tol.h"
#include "base/vec3.h"

/* The facet the walk rolls to from the part of arc e between unit vectors x
 * and y on it (both on one side of s0), or -1 when that part is too short to
 * hold a point farther than margin from both ends (a chord of 2 margins
 * would just hold its midpoint; the second factor 2 is slack). */
static int roll_between(const pd_hull *h, pd_vec3 com, int v, const pd_star_edge *e, pd_vec3 x,
                        pd_vec3 y, double margin)
{
    if (!(v3_dist(x, y) > 4.0 * margin))
        return -1;
    return pd_star_roll(h, com, v, e, v3_unit(v3_add(x, y)));
}

/* unit(a x b) turned towards side, or the zero vector when either is not
 * clear of round-off (side within PD_TOL_DESCENT_MAP of the plane). */
static pd_vec3 plane_towards(pd_vec3 a, pd_vec3 b, pd_vec3 side)
{
    pd_vec3 m = v3_unit(v3_cross(a, b));
    double d = v3_dot(m, side);
    if (!(fabs(d) > PD_TOL_DESCENT_MAP))
        return v3(0.0, 0.0, 0.0);
    return d > 0.0 ? m : v3_neg(m);
}

/* Fills arc k of vertex v's star (see the header comment); leaves it
 * unmapped (margin INFINITY) where the walk must decide. */
static void map_arc(const pd_hull *h, const pd_star *s, pd_vec3 com, int v, int k,
                    pd_descent_arc *out)
{
    const pd_star_edge *e = &s->edge[k];
    out->ma = out->mb = out->ms = v3(0.0, 0.0, 0.0);
    out->margin = INFINITY;
    out->pos = out->neg = -1;
    double lambda = pd_star_lambda(h, com, v, e);
    if (!(lambda > 0.0 && lambda < 1.0))
        return;
    /* The neighbouring boundaries: the other edges of v on facets left and
     * right. */
    int ka = -1, kb = -1;
    for (int j = s->start[v]; j < s->start[v + 1]; j++) {
        if (s->edge[j].right == e->left)
            ka = j;
        if (s->edge[j].left == e->right)
            kb = j;
    }
    if (ka < 0 || kb < 0 || ka == k || kb == k || ka == kb)
        return;
    const pd_star_edge *ea = &s->edge[ka], *eb = &s->edge[kb];
    pd_vec3 na = h->normal[e->left], nb = h->normal[e->right];
    pd_vec3 ca = v3_cross(e->u, ea->u), cb = v3_cross(e->u, eb->u);
    double sine = fmin(1.0, fmin(v3_norm(ca) / (e->len * ea->len), v3_norm(cb) / (e->len * eb->len)));
    if (!(sine > 0.0))
        return;
    ca = v3_unit(ca);
    cb = v3_unit(cb);
    if (v3_dot(ca, na) < 0.0)
        ca = v3_neg(ca);
    if (v3_dot(cb, nb) < 0.0)
        cb = v3_neg(cb);
    for (int j = s->start[v]; j < s->start[v + 1]; j++) {
        const pd_star_edge *o = &s->edge[j];
        if (j != k && j != ka && j != kb &&
            !(v3_dot(o->u, ca) >= PD_TOL_DESCENT_MAP * o->len &&
              v3_dot(o->u, cb) >= PD_TOL_DESCENT_MAP * o->len))
            return;
    }
    double margin = PD_TOL_DESCENT_MAP / sine + PD_TOL_ANGLE +
                    fmax(v3_dist(na, ca), v3_dist(nb, cb));
    pd_vec3 u = v3_sub(h->verts[v], com);
    pd_vec3 ma = plane_towards(u, ca, cb), mb = plane_towards(u, cb, ca);
    if (v3_dot(ma, ma) == 0.0 || v3_dot(mb, mb) == 0.0)
        return;
    pd_vec3 s0 = v3_sub(u, v3_scale(e->u, lambda)); /* foot of com on the edge line, from com */
    pd_vec3 ms = ma;
    int pos, neg;
    if (v3_dot(ma, s0) > 0.0 && v3_dot(mb, s0) > 0.0) {
        /* The saddle is on the arc: the part rolls away from it. */
        ms = plane_towards(u, s0, ca);
        if (v3_dot(ms, ms) == 0.0)
            return;
        pd_vec3 s0u = v3_unit(s0);
        pos = roll_between(h, com, v, e, ca, s0u, margin);
        neg = roll_between(h, com, v, e, s0u, cb, margin);
    } else {
        pos = neg = roll_between(h, com, v, e, ca, cb, margin);
    }
    out->ma = ma;
    out->mb = mb;
    out->ms = ms;
    out->margin = margin;
    out->pos = pos;
    out->neg = neg;
}

pd_status pd_descent_map_build(const pd_hull *h, const pd_star *s, pd_vec3 com,
                               pd_descent_map *map)
{
    map->hull = h;
    map->star = s;
    map->com = com;
    int n = s->start[h->nverts];
    map->arc = malloc(sizeof *map->arc * (size_t)(n > 0 ? n : 1));
    if (!map->arc)
        return PD_ERR_NOMEM;
    for (int v = 0; v < h->nverts; v++) {
        /* How far inside v's cone any of its facet normals lies (<= 0 when
         * all are on or outside its boundary, as exact normals are). */
        double in = 0.0;
        for (int k = s->start[v]; k < s->start[v + 1]; k++) {
            pd_vec3 nf = h->normal[s->edge[k].left];
            double least = INFINITY;
            for (int j = s->start[v]; j < s->start[v + 1]; j++)
                least = fmin(least, v3_dot(s->edge[j].u, nf) / s->edge[j].len);
            in = fmax(in, least);
        }
        double cone = PD_TOL_ANGLE + PD_TOL_DESCENT_MAP + in;
        for (int k = s->start[v]; k < s->start[v + 1]; k++) {
            map_arc(h, s, com, v, k, &map->arc[k]);
            map->arc[k].cone = cone * s->edge[k].len;
        }
    }
    return PD_OK;
}

void pd_descent_map_free(pd_descent_map *map)
{
    free(map->arc);
    map->arc = NULL;
}

int pd_descent_map_facet(const pd_descent_map *map, pd_vec3 g, int v)
{
    const pd_star *s = map->star;
    int k0 = s->start[v], k1 = s->start[v + 1];
    for (int k = k0; k < k1; k++)
        if (!(v3_dot(s->edge[k].u, g) > map->arc[k].cone))
            return -1;
    for (int k = k0; k < k1; k++) {
        const pd_descent_arc *a = &map->arc[k];
        if (v3_dot(a->ma, g) > a->margin && v3_dot(a->mb, g) > a->margin) {
            /* Lunes of far arcs do not overlap: this is the only candidate. */
            double side = v3_dot(a->ms, g);
            return side > a->margin ? a->pos : side < -a->margin ? a->neg : -1;
        }
    }
    return -1;
}

pd_status pd_descent_lookup(const pd_descent_map *map, pd_vec3 g, int *facet, int *hint)
{
    const pd_hull *h = map->hull;
    int v = pd_star_support(h, map->star, g, hint && *hint >= 0 && *hint < h->nverts ? *hint : 0);
    if (hint)
        *hint = v;
    int f = pd_descent_map_facet(map, g, v);
    if (f >= 0) {
        *facet = f;
        return PD_OK;
    }
    return pd_descend(h, map->star, map->com, g, facet, &v);
}
