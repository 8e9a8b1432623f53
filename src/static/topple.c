/* topple.c: the quasi-static graph (QSG): where each unstable facet topples.
 *
 * Orientations are gravity directions g on the unit sphere of the part's
 * frame. Resting on the floor with gravity g, the centre of mass c is at height
 *   h(g) = max over hull points x of (x - c) . g
 * (the support function), and quasi-static motion is steepest descent of h.
 * The sphere is tiled by the hull's normal cones: a facet is a point (its
 * normal), an edge an arc between its two facets' normals, a vertex the
 * spherical polygon around it. Descent from a facet normal n_f:
 *  - the foot of c on the facet lies nearest an edge's interior: the part
 *    rotates about that edge and lands on the facet across it;
 *  - it lies nearest a vertex v: the part pivots about v, g moving on the
 *    great circle away from the direction of v - c, until it leaves v's cone
 *    across the arc of an edge (v, w). There the projection of c on the edge
 *    line decides: inside the segment, the part rotates about the edge to the
 *    arc's lower end (a facet that may share only v with the start); beyond
 *    w, it pivots about w and the walk goes on.
 * h falls strictly along the way, so the walk ends. The paper's rule
 * (PD_TOPPLE_EDGE) instead always topples across the edge of the facet beyond
 * whose line the foot lies farthest, which keeps links between edge-adjacent
 * facets. */
#include <stdlib.h>
#include "base/fail.h"
#include "posedrop/tolerances.h"
#include "base/base_tol.h"
#include "static/static_tol.h"
#include "static/static_internal.h"
#include "base/vec3.h"

/* The component of x perpendicular to the unit vector g. */
static pd_vec3 tangential(pd_vec3 x, pd_vec3 g)
{
    return v3_sub(x, v3_scale(g, v3_dot(x, g)));
}

/* 1 if g is within PD_TOL_ANGLE of the unit vector n (chord ~ angle there). */
static int at_normal(pd_vec3 g, pd_vec3 n)
{
    pd_vec3 d = v3_sub(g, n);
    return v3_dot(d, d) <= PD_TOL_ANGLE * PD_TOL_ANGLE;
}

/* Steepest descent pivoting about vertex v from gravity direction g in its
 * cone, moving along the unit tangent d; f (or -1) is the facet it starts
 * from, which it must not land back on. On a
 * finely tessellated smooth part the walk crosses tens of vertex cones, so
 * each step is kept free of trigonometry: on g(s) = g cos s + d sin s the
 * boundary u . g(s) = A cos s + B sin s (A = u.g >= 0, B = u.d) is reached
 * at the angle of the vector (-B, A), and the first boundary reached is the
 * one whose vector turns least, found by cross products; the exit point is
 * (-B g + A d) / |(A, B)|, a unit vector since g and d are orthonormal. */
static pd_status walk(const pd_hull *h, const pd_star *s, pd_vec3 com, int f, int v, pd_vec3 g,
                     pd_vec3 d, int *next)
{
    int limit = 2 * h->nverts + 8; /* every pivot lowers h, so vertices don't repeat */
    for (int step = 0; step < limit; step++) {
        double bx = 0.0, by = -1.0; /* direction of the best exit so far */
        const pd_star_edge *exit = NULL;
        for (int k = s->start[v]; k < s->start[v + 1]; k++) {
            const pd_star_edge *e = &s->edge[k];
            double A = v3_dot(e->u, g), B = v3_dot(e->u, d), x = -B, y = A;
            if (A <= PD_TOL_ANGLE * e->len) {
                if (B > 0.0)
                    continue; /* on this boundary but moving inward */
                x = 1.0;      /* leaving through it at once */
                y = 0.0;
            }
            if (!exit || x * by - y * bx > 0.0) {
                bx = x;
                by = y;
                exit = e;
            }
        }
        if (!exit)
            return PD_ERR_INTERNAL;
        pd_vec3 g1 = g;
        if (by > 0.0)
            g1 = v3_scale(v3_add(v3_scale(g, bx), v3_scale(d, by)), 1.0 / sqrt(bx * bx + by * by));
        /* Leaving through a corner of the cone: the part lands on that facet. */
        if (exit->left != f && at_normal(g1, h->normal[exit->left])) {
            *next = exit->left;
            return PD_OK;
        }
        if (exit->right != f && at_normal(g1, h->normal[exit->right])) {
            *next = exit->right;
            return PD_OK;
        }
        double lambda = pd_star_lambda(h, com, v, exit);
        pd_vec3 dw = tangential(v3_sub(com, h->verts[exit->to]), g1);
        double ndw = v3_norm(dw);
        if (lambda < 1.0 || ndw <= PD_TOL_ANGLE * exit->len) {
            /* Centre of mass over the segment (lambda > 0 whenever the edge
             * was reached by pivoting about v; round-off below 0 is clamped
             * here too): roll about the edge to the lower end of its arc. */
            *next = pd_star_roll(h, com, v, exit, g1);
            return PD_OK;
        }
        /* Beyond w: w takes over as the pivot. */
        v = exit->to;
        g = g1;
        d = v3_scale(dw, 1.0 / ndw);
    }
    return PD_ERR_NO_CONVERGENCE;
}

pd_status pd_descend(const pd_hull *h, const pd_star *s, pd_vec3 com, pd_vec3 g, int *facet,
                     int *hint)
{
    int v = pd_star_support(h, s, g, hint && *hint >= 0 && *hint < h->nverts ? *hint : 0);
    if (hint)
        *hint = v;
    /* Resting on a facet already (g at its normal): no motion from there
     * but the facet's own toppling, which its rest[] records. */
    for (int k = s->start[v]; k < s->start[v + 1]; k++)
        if (at_normal(g, h->normal[s->edge[k].left])) {
            *facet = s->edge[k].left;
            return PD_OK;
        }
    pd_vec3 t = tangential(v3_sub(com, h->verts[v]), g);
    double nt = v3_norm(t);
    if (nt == 0.0) /* balanced on the vertex: a maximum; any way down will do */
        t = tangential(v3_sub(h->verts[s->edge[s->start[v]].to], h->verts[v]), g), nt = v3_norm(t);
    return walk(h, s, com, -1, v, g, v3_scale(t, 1.0 / nt), facet);
}

/* Resolves rest[] by following next[] (heights fall along it, so chains are
 * at most nfacets long; a longer one is a cycle and a bug). */
static pd_status resolve_rest(pd_static_result *res, pd_diag *diag)
{
    pd_facet_result *fr = res->facets;
    for (int f = 0; f < res->nfacets; f++)
        fr[f].rest = fr[f].stable ? f : -1;
    for (int f = 0; f < res->nfacets; f++) {
        int g = f, len = 0;
        while (fr[g].rest < 0) {
            g = fr[g].next;
            if (++len > res->nfacets)
                return pd_fail(diag, PD_ERR_INTERNAL, "quasi-static graph has a cycle at facet %d",
                               f + 1);
        }
        int r = fr[g].rest;
        for (g = f; fr[g].rest < 0; g = fr[g].next)
            fr[g].rest = r;
    }
    return PD_OK;
}

/* Where knife facet f topples: across its best edge (the paper's rule) when
 * that lowers the centre of mass, else across the edge within the knife
 * band whose neighbour is lowest; -1 when none is lower by more than
 * PD_TOL_KNIFE_DROP_REL (then f is stable after all). */
static int knife_exit(const pd_hull *hull, pd_vec3 com, const facet_geom *g,
                      const pd_static_result *res, int f)
{
    int base = hull->facet_start[f], k = hull->facet_start[f + 1] - base;
    double top = res->facets[f].height - PD_TOL_KNIFE_DROP_REL * hull->size;
    int best = hull->facet_adj[base + g->best_edge];
    if (res->facets[best].height < top)
        return best;
    double knife = PD_TOL_KNIFE_REL * hull->size;
    int out = -1;
    for (int i = 0; i < k; i++) {
        int nb = hull->facet_adj[base + i];
        if (pd_facet_edge_inside(hull, com, f, i) <= knife && res->facets[nb].height < top &&
            (out < 0 || res->facets[nb].height < res->facets[out].height))
            out = nb;
    }
    return out;
}

/* Knife facets with no way down are stable: the centre of mass sits in a
 * valley that only round-off made look like a ridge. One warning names how
 * many, and the first. */
static void settle_flat_knives(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                               pd_static_result *res, int *exit_of, pd_diag *diag)
{
    int count = 0, first = -1;
    for (int f = 0; f < res->nfacets; f++) {
        pd_facet_result *r = &res->facets[f];
        exit_of[f] = r->knife ? knife_exit(hull, com, &geom[f], res, f) : -1;
        if (r->knife && exit_of[f] < 0) {
            r->knife = 0;
            r->stable = 1;
            if (count++ == 0)
                first = f;
        }
    }
    if (count > 0)
        pd_warn(diag,
                "%d facet%s (the first is facet %d): the centre of mass projects within %.3g m "
                "of the boundary, but no facet across it is lower; counted as stable",
                count, count > 1 ? "s" : "", first + 1, PD_TOL_KNIFE_REL * hull->size);
}

pd_status pd_topple_graph(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                          pd_topple_rule rule, pd_static_result *res, pd_diag *diag)
{
    pd_star star = {NULL, NULL};
    int *exit_of = malloc(sizeof *exit_of * (size_t)(hull->nfacets > 0 ? hull->nfacets : 1));
    if (!exit_of)
        return PD_ERR_NOMEM;
    settle_flat_knives(hull, com, geom, res, exit_of, diag);
    pd_status st = PD_OK;
    if (rule == PD_TOPPLE_DESCENT)
        st = pd_star_build(hull, &star);
    for (int f = 0; f < hull->nfacets && st == PD_OK; f++) {
        pd_facet_result *r = &res->facets[f];
        const facet_geom *g = &geom[f];
        int base = hull->facet_start[f];
        r->next = -1;
        if (r->stable)
            continue;
        if (r->knife)
            r->next = exit_of[f];
        else if (rule == PD_TOPPLE_EDGE)
            r->next = hull->facet_adj[base + g->best_edge];
        else if (g->near_vertex < 0)
            r->next = hull->facet_adj[base + g->near_edge];
        else
            st = walk(hull, &star, com, f, g->near_vertex, hull->normal[f],
                      v3_unit(tangential(v3_sub(com, hull->verts[g->near_vertex]),
                                         hull->normal[f])),
                      &r->next);
        if (st == PD_ERR_NO_CONVERGENCE)
            st = pd_fail(diag, st, "quasi-static descent from facet %d did not end", f + 1);
        else if (st == PD_ERR_INTERNAL)
            st = pd_fail(diag, st, "quasi-static descent from facet %d left no vertex cone", f + 1);
        if (st != PD_OK)
            break;
        /* Every link must lower the centre of mass: that is what makes the
         * graph acyclic and the propagation well defined. */
        double rise = res->facets[r->next].height - r->height;
        if (r->next == f || rise > PD_TOL_HEIGHT_REL * hull->size)
            st = pd_fail(diag, PD_ERR_INTERNAL,
                         "quasi-static link from facet %d to %d raises the centre of mass by %.3g m",
                         f + 1, r->next + 1, rise);
    }
    pd_star_free(&star);
    free(exit_of);
    if (st == PD_OK)
        st = resolve_rest(res, diag);
    return st;
}
