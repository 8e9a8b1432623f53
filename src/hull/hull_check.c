/* hull_check.c: pd_hull_check, an independent validation of a pd_hull.
 *
 * Checks only what the structure promises, from the structure alone: unit
 * normals, loops of >= 3 valid corners, corners on their planes, convexity
 * across every edge (the neighbour's corners are below the plane), symmetric
 * adjacency, every corner on >= 3 facets, Euler's V - E + F = 2, and the input
 * points inside. Plane distances get PD_TOL_PLANE_REL * size plus the
 * round-off of evaluating n . x - offset on coordinates far from the origin
 * (a part 1e6 m from the origin has coordinates rounded to 1e-10 m, which no
 * relative tolerance can absorb). */
#include <float.h>
#include <stdlib.h>
#include "base/fail.h"
#include "posedrop/hull.h"
#include "posedrop/tolerances.h"
#include "base/base_tol.h"
#include "base/vec3.h"

/* Most facet steps a point-location walk may take before the check falls
 * back to testing the point against every facet. */
#define WALK_STEPS_PER_FACET 4
/* Relative slack of the walk's side tests (see locate). */
#define WALK_SLACK 1e-14

/* Signed distance of x above facet f and the bound on its round-off (about
 * 4 roundings on terms of the size of |n_i x_i| and |offset|; 8 for margin). */
static double plane_dist(const pd_hull *h, int f, pd_vec3 x, double *err)
{
    pd_vec3 n = h->normal[f];
    *err = 8.0 * DBL_EPSILON *
           (fabs(n.x * x.x) + fabs(n.y * x.y) + fabs(n.z * x.z) + fabs(h->offset[f]));
    return v3_dot(n, x) - h->offset[f];
}

/* Facet whose cone from c contains direction d (a visibility walk on the
 * facets' central projection), or -1 if the walk does not settle. The choice
 * among violated edges rotates with a counter, which keeps the walk from
 * cycling on degenerate configurations and the result deterministic. */
static int locate(const pd_hull *h, pd_vec3 c, pd_vec3 d, int f, unsigned *rot)
{
    int maxsteps = WALK_STEPS_PER_FACET * h->nfacets + 16;
    for (int step = 0; step < maxsteps; step++) {
        int s = h->facet_start[f], k = h->facet_start[f + 1] - s;
        int nviol = 0, pick = -1;
        unsigned want = (*rot)++;
        for (int i = 0; i < k; i++) {
            pd_vec3 a = v3_sub(h->verts[h->facet_vert[s + i]], c);
            pd_vec3 b = v3_sub(h->verts[h->facet_vert[s + (i + 1) % k]], c);
            pd_vec3 e = v3_cross(a, b);
            /* A direction within WALK_SLACK of an edge plane counts as
             * inside: directions through a vertex lie on several edge
             * planes at once and round-off must not make the walk circle
             * that vertex. The plane test then errs by at most ~1e-14 of
             * the distance from c, far below PD_TOL_PLANE_REL. */
            if (v3_dot(e, d) < -WALK_SLACK * v3_norm(e) * v3_norm(d)) {
                nviol++;
                if (pick < 0 || want % (unsigned)nviol == 0)
                    pick = s + i;
            }
        }
        if (nviol == 0)
            return f;
        f = h->facet_adj[pick];
    }
    return -1;
}

typedef struct {
    unsigned long key;
    int idx;
} walk_key;

static int cmp_walk_key(const void *a, const void *b)
{
    const walk_key *x = a, *y = b;
    if (x->key != y->key)
        return (x->key > y->key) - (x->key < y->key);
    return (x->idx > y->idx) - (x->idx < y->idx);
}

/* Morton code of a unit direction quantised to 10 bits per axis: sorting by
 * it keeps nearby directions together. */
static unsigned long direction_key(pd_vec3 u)
{
    const double c[3] = {u.x, u.y, u.z};
    unsigned long key = 0;
    for (int k = 0; k < 3; k++) {
        double t = (c[k] + 1.0) * 511.5;
        unsigned long q = t > 0.0 ? (unsigned long)fmin(t, 1023.0) : 0;
        for (int b = 0; b < 10; b++)
            key |= ((q >> b) & 1ul) << (3 * b + k);
    }
    return key;
}

pd_status pd_hull_check(const pd_hull *h, const pd_vec3 *pts, int npts, pd_diag *diag)
{
    if (!h || npts < 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_hull_check: %s", h ? "negative point count" : "NULL hull");
    if (h->nfacets < 4 || h->nverts < 4 || !h->verts || !h->normal || !h->offset || !h->facet_start ||
        !h->facet_vert || !h->facet_adj || !(h->size > 0.0))
        return pd_fail(diag, PD_ERR_INTERNAL, "hull check: missing arrays or fewer than 4 facets/vertices");
    double tol = PD_TOL_PLANE_REL * h->size;
    int nf = h->nfacets, nv = h->nverts;
    if (h->facet_start[0] != 0)
        return pd_fail(diag, PD_ERR_INTERNAL, "hull check: facet_start[0] = %d", h->facet_start[0]);
    for (int f = 0; f < nf; f++) {
        double len = v3_norm(h->normal[f]);
        /* A normal off unit length by d tilts plane distances like an angle
         * error d: PD_TOL_ANGLE. */
        if (!(fabs(len - 1.0) <= PD_TOL_ANGLE))
            return pd_fail(diag, PD_ERR_INTERNAL, "hull check: facet %d normal has length %.17g", f, len);
        int s = h->facet_start[f], k = h->facet_start[f + 1] - s;
        if (k < 3)
            return pd_fail(diag, PD_ERR_INTERNAL, "hull check: facet %d has %d corners", f, k);
        for (int i = s; i < s + k; i++) {
            int v = h->facet_vert[i], g = h->facet_adj[i];
            if (v < 0 || v >= nv || g < 0 || g >= nf || g == f)
                return pd_fail(diag, PD_ERR_INTERNAL, "hull check: facet %d corner %d: vertex %d, neighbour %d",
                               f, i - s, v, g);
        }
    }
    int *deg = calloc((size_t)nv, sizeof *deg);
    if (!deg)
        return pd_fail(diag, PD_ERR_NOMEM, "hull check: out of memory");
    long nedges2 = 0;
    pd_status st = PD_OK;
    for (int f = 0; f < nf && st == PD_OK; f++) {
        int s = h->facet_start[f], k = h->facet_start[f + 1] - s;
        nedges2 += k;
        pd_vec3 loopn = v3(0, 0, 0);
        for (int i = 0; i < k && st == PD_OK; i++) {
            int a = h->facet_vert[s + i], b = h->facet_vert[s + (i + 1) % k], g = h->facet_adj[s + i];
            deg[a]++;
            loopn = v3_add(loopn, v3_cross(v3_sub(h->verts[a], h->verts[h->facet_vert[s]]),
                                           v3_sub(h->verts[b], h->verts[h->facet_vert[s]])));
            double err, d = plane_dist(h, f, h->verts[a], &err);
            if (!(fabs(d) <= tol + err)) {
                st = pd_fail(diag, PD_ERR_INTERNAL, "hull check: corner %d is %.3g off the plane of facet %d "
                             "(tolerance %.3g)", a, d, f, tol + err);
                break;
            }
            int gs = h->facet_start[g], gk = h->facet_start[g + 1] - gs, twin = 0;
            for (int j = 0; j < gk; j++) {
                int c = h->facet_vert[gs + j];
                if (c == b && h->facet_vert[gs + (j + 1) % gk] == a)
                    twin = h->facet_adj[gs + j] == f;
                d = plane_dist(h, f, h->verts[c], &err);
                if (!(d <= tol + err)) {
                    st = pd_fail(diag, PD_ERR_INTERNAL, "hull check: not convex: corner %d of facet %d is %.3g "
                                 "above facet %d (tolerance %.3g)", c, g, d, f, tol + err);
                    break;
                }
            }
            if (st == PD_OK && !twin)
                st = pd_fail(diag, PD_ERR_INTERNAL, "hull check: edge %d -> %d of facet %d has no twin in "
                             "facet %d", a, b, f, g);
        }
        /* The loop must turn counter-clockwise seen from outside. */
        if (st == PD_OK && !(v3_dot(loopn, h->normal[f]) > 0.0))
            st = pd_fail(diag, PD_ERR_INTERNAL, "hull check: facet %d loop is not counter-clockwise", f);
    }
    for (int v = 0; v < nv && st == PD_OK; v++)
        if (deg[v] < 3)
            st = pd_fail(diag, PD_ERR_INTERNAL, "hull check: vertex %d is on %d facets (need >= 3)", v, deg[v]);
    free(deg);
    if (st != PD_OK)
        return st;
    if (nedges2 % 2 != 0 || nv - nedges2 / 2 + nf != 2)
        return pd_fail(diag, PD_ERR_INTERNAL, "hull check: Euler: V - E + F = %d - %ld + %d != 2", nv,
                       nedges2 / 2, nf);
    if (!pts)
        return PD_OK;
    pd_vec3 c = v3(0, 0, 0);
    for (int v = 0; v < nv; v++)
        c = v3_add(c, v3_sub(h->verts[v], h->verts[0]));
    c = v3_add(h->verts[0], v3_scale(c, 1.0 / nv));
    /* Each point is tested against the facet its ray from the centroid
     * leaves through (inside iff below that facet). Points are walked to in
     * the order of a Morton code of their direction, so each walk starts
     * from a nearby facet and is short. Few facets: test them all. */
    int brute = (double)npts * nf <= 4e7;
    walk_key *order = NULL;
    if (!brute) {
        order = malloc(sizeof *order * (size_t)npts);
        if (!order)
            return pd_fail(diag, PD_ERR_NOMEM, "hull check: out of memory");
        for (int i = 0; i < npts; i++) {
            order[i].key = direction_key(v3_unit(v3_sub(pts[i], c)));
            order[i].idx = i;
        }
        qsort(order, (size_t)npts, sizeof *order, cmp_walk_key);
    }
    int f = 0;
    unsigned rot = 0;
    for (int j = 0; j < npts; j++) {
        int i = brute ? j : order[j].idx;
        int g = brute ? -1 : locate(h, c, v3_sub(pts[i], c), f, &rot);
        int first = g >= 0 ? g : 0, last = g >= 0 ? g + 1 : nf;
        for (int k = first; k < last; k++) {
            double err, d = plane_dist(h, k, pts[i], &err);
            if (!(d <= tol + err)) {
                free(order);
                return pd_fail(diag, PD_ERR_INTERNAL, "hull check: input point %d is %.3g outside facet %d "
                               "(tolerance %.3g)", i, d, k, tol + err);
            }
        }
        if (g >= 0)
            f = g;
    }
    free(order);
    return PD_OK;
}
