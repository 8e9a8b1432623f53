/* mesh_orient.c: consistent, outward orientation of a closed triangle mesh.
 *
 * Three steps, none of which touches the mesh until all have succeeded, so a
 * failure leaves it as it was:
 *  1. Edge adjacency. Every directed edge of every triangle is keyed by its
 *     unordered vertex pair and the keys are sorted (by a count of the lower
 *     vertex, then within its few edges: linear on the usual meshes, and
 *     deterministic, unlike a hash whose order depends on its size). A closed
 *     2-manifold has every key exactly twice.
 *  2. Relative orientation. Two triangles sharing an edge agree when they
 *     traverse it in opposite directions. A breadth-first search per connected
 *     component fixes each triangle's flip relative to the component's first
 *     triangle; a cycle demanding both flips at once means the surface is
 *     non-orientable (a Moebius strip or projective plane), and no flipping can
 *     help.
 *  3. Global sign. Each component is now oriented up to one sign. A component
 *     nested inside an even number of others is an outer shell and must
 *     enclose positive volume; inside an odd number it bounds a void and must
 *     enclose negative volume, so that summing signed volumes over all
 *     components gives the material's volume. Nesting is decided by the
 *     winding number of each other component at a point of this one.
 *
 * Triangles with a repeated vertex index (collapsed to an edge or a point) have
 * no area, no normal and no meaningful edges; they are left out of all three
 * steps, left untouched, counted in a warning, and contribute nothing to the
 * mass properties either (pd_mass_compute skips them the same way). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "posedrop/mass.h"
#include "posedrop/tolerances.h"
#include "mesh/mesh_tol.h"
#include "base/fail.h"
#include "mesh/mesh_internal.h"
#include "base/vec3.h"

/* How many points of a component are tried before accepting one whose
 * winding numbers are ambiguous (see PD_TOL_WINDING). Each try costs a pass
 * over the other components' triangles; 16 is plenty for shells that merely
 * touch along a few faces, and bounds the cost for pathological input. */
#define ORIENT_MAX_PROBES 16

/* One directed edge of triangle tri, starting at its corner k (code 3 tri +
 * k), keyed by the unordered pair (lo, hi) of its ends; lo is the run it is
 * stored in (pair_edges), so it is not stored. */
typedef struct half_edge {
    int hi, code;
} half_edge;

static int cmp_half_edge(const void *pa, const void *pb)
{
    const half_edge *a = pa, *b = pb;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return (a->code > b->code) - (a->code < b->code);
}

static int tri_degenerate(const int t[3])
{
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

/* Corner c of triangle t under a tentative flip: a flip swaps corners 1 and 2,
 * which reverses the triangle's traversal. */
static int corner(const pd_mesh *m, int t, int flip, int c)
{
    return m->tris[t][flip && c ? 3 - c : c];
}

/* Solid angle subtended at the origin by the triangle a, b, c (vertices
 * relative to the point), signed by the triangle's orientation. Van Oosterom
 * and Strackee (1983): tan(omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| +
 * (b.c)|a| + (c.a)|b|); atan2 keeps it right for angles above pi. */
static double solid_angle(pd_vec3 a, pd_vec3 b, pd_vec3 c)
{
    double la = v3_norm(a), lb = v3_norm(b), lc = v3_norm(c);
    double num = v3_dot(a, v3_cross(b, c));
    double den = la * lb * lc + v3_dot(a, b) * lc + v3_dot(b, c) * la + v3_dot(c, a) * lb;
    /* den <= 0 with num ~ 0: the point lies on the closed triangle (in its
     * plane, to PD_TOL_PLANE_REL of its distances, and within its corners),
     * where the angle jumps between -2 pi and 2 pi on the sign of round-off.
     * Counting 0 instead leaves the winding number at a half-integer, which
     * the caller recognises as "on the surface" and moves to another point. */
    if (den <= 0.0 && fabs(num) <= PD_TOL_PLANE_REL * la * lb * lc)
        return 0.0;
    return 2.0 * atan2(num, den);
}

/* Per connected component: its triangles are list[start .. start+count), in
 * BFS order; vol6 is six times its signed volume under the tentative flips;
 * lo/hi its bounding box. */
typedef struct component {
    int start, count;
    double vol6;
    pd_vec3 lo, hi;
} component;

/* Winding number of component d (tentative flips) at p, normalised so that
 * the inside of d counts +1 whichever way d is tentatively oriented. */
static double winding(const pd_mesh *m, const component *d, const int *list,
                      const unsigned char *flip, pd_vec3 p)
{
    if (d->vol6 == 0.0)
        return 0.0; /* a flat component encloses nothing */
    if (p.x < d->lo.x || p.y < d->lo.y || p.z < d->lo.z || p.x > d->hi.x || p.y > d->hi.y ||
        p.z > d->hi.z)
        return 0.0; /* outside its bounding box: cannot be inside it */
    double sum = 0.0;
    for (int i = 0; i < d->count; i++) {
        int t = list[d->start + i];
        pd_vec3 a = v3_sub(m->verts[corner(m, t, flip[t], 0)], p);
        pd_vec3 b = v3_sub(m->verts[corner(m, t, flip[t], 1)], p);
        pd_vec3 c = v3_sub(m->verts[corner(m, t, flip[t], 2)], p);
        sum += solid_angle(a, b, c);
    }
    double w = sum / (4.0 * M_PI);
    return d->vol6 > 0.0 ? w : -w;
}

/* Number of other components enclosing component c, judged at a point of c:
 * the centroid of one of its triangles. A centroid lying on another component
 * (shells touching face to face) gives a half-integer winding number; then the
 * next triangle's centroid is tried. */
static int nesting_depth(const pd_mesh *m, const component *comps, int ncomps, int c,
                         const int *list, const unsigned char *flip)
{
    int first_depth = -1;
    int nprobes = comps[c].count < ORIENT_MAX_PROBES ? comps[c].count : ORIENT_MAX_PROBES;
    for (int probe = 0; probe < nprobes; probe++) {
        int t = list[comps[c].start + probe];
        pd_vec3 p = v3_scale(v3_add(v3_add(m->verts[m->tris[t][0]], m->verts[m->tris[t][1]]),
                                    m->verts[m->tris[t][2]]),
                             1.0 / 3.0);
        int depth = 0, ambiguous = 0;
        for (int d = 0; d < ncomps; d++) {
            if (d == c)
                continue;
            double w = winding(m, &comps[d], list, flip, p);
            if (fabs(w - nearbyint(w)) > PD_TOL_WINDING)
                ambiguous = 1;
            depth += w > 0.5;
        }
        if (!ambiguous)
            return depth;
        if (first_depth < 0)
            first_depth = depth;
    }
    return first_depth;
}

/* Sorts the directed edges and pairs them: nbr[3t+k] is the triangle across
 * the edge starting at corner k of t (-1 for degenerate t), same[3t+k] is 1
 * when that neighbour traverses the edge in the same direction (so exactly one
 * of the two must flip). Fails on the first edge, in sorted order, that is not
 * used by exactly two triangles. */
/* 1 when *cancel (may be NULL) is set, read every 4,096 calls: each step
 * of the loops that call it is well under a microsecond. */
static int poll_cancel(pd_cancel_flag *cancel, unsigned *n)
{
    return cancel && ++*n % 4096 == 0 && atomic_load_explicit(cancel, memory_order_relaxed);
}

static int half_edge_less(const half_edge *a, const half_edge *b)
{
    return cmp_half_edge(a, b) < 0;
}

static pd_status pair_edges(const pd_mesh *m, half_edge *he, int *nbr, unsigned char *same,
                            pd_cancel_flag *cancel, pd_diag *diag)
{
    unsigned polls = 0;
    /* The order of one sort by (lo, hi, tri, k), made in linear time: the
     * edges counted and placed by lo in order of triangle and corner (so
     * each lo's run is already in (tri, k) order), then each run sorted by
     * hi, stably by insertion when short (the usual star), by qsort on the
     * whole key when long (a fan about one corner): no log factor over all
     * the edges, and the same order, so the same edge is reported first. */
    int *at = calloc((size_t)m->nverts + 1, sizeof *at);
    if (!at)
        return pd_fail(diag, PD_ERR_NOMEM, "orient: out of memory for %d vertices", m->nverts);
    for (int t = 0; t < m->ntris; t++) {
        for (int k = 0; k < 3; k++)
            nbr[3 * t + k] = -1;
        if (tri_degenerate(m->tris[t]))
            continue;
        for (int k = 0; k < 3; k++) {
            int a = m->tris[t][k], b = m->tris[t][(k + 1) % 3];
            at[(a < b ? a : b)]++;
        }
    }
    for (int v = 0, sum = 0; v <= m->nverts; v++) {
        int c = at[v];
        at[v] = sum;
        sum += c;
    }
    for (int t = 0; t < m->ntris; t++) {
        if (poll_cancel(cancel, &polls)) {
            free(at);
            return PD_ERR_CANCELLED;
        }
        if (tri_degenerate(m->tris[t]))
            continue;
        for (int k = 0; k < 3; k++) {
            int a = m->tris[t][k], b = m->tris[t][(k + 1) % 3];
            half_edge *h = &he[at[a < b ? a : b]++];
            h->hi = a < b ? b : a;
            h->code = 3 * t + k;
        }
    }
    /* at[v] is now the end of v's run. */
    for (int v = 0, first = 0; v < m->nverts; v++) {
        if (poll_cancel(cancel, &polls)) {
            free(at);
            return PD_ERR_CANCELLED;
        }
        int n = at[v] - first;
        half_edge *r = he + first;
        if (n > 32) {
            qsort(r, (size_t)n, sizeof *r, cmp_half_edge);
        } else {
            for (int i = 1; i < n; i++) {
                half_edge x = r[i];
                int j = i;
                for (; j > 0 && half_edge_less(&x, &r[j - 1]); j--)
                    r[j] = r[j - 1];
                r[j] = x;
            }
        }
        first = at[v];
    }
    pd_status st = PD_OK;
    for (int v = 0, first = 0; v < m->nverts && st == PD_OK; first = at[v], v++)
        for (int i = first; i < at[v];) {
            int j = i + 1;
            while (j < at[v] && he[j].hi == he[i].hi)
                j++;
            int pt = he[i].code / 3, pk = he[i].code % 3;
            if (j - i != 2) {
                st = pd_fail(diag, PD_ERR_NOT_CLOSED,
                             "orient: edge (%d, %d) is used by %d face%s (triangle %d%s): %s", v,
                             he[i].hi, j - i, j - i == 1 ? "" : "s", pt,
                             j - i == 1 ? "" : " and others",
                             j - i == 1 ? "boundary edge, the mesh has a hole"
                                        : "non-manifold edge, more than two faces meet there");
                break;
            }
            int qt = he[i + 1].code / 3, qk = he[i + 1].code % 3;
            /* The edge's direction in each triangle: does it run lo -> hi? */
            int pfwd = m->tris[pt][pk] == v, qfwd = m->tris[qt][qk] == v;
            nbr[3 * pt + pk] = qt;
            nbr[3 * qt + qk] = pt;
            same[3 * pt + pk] = same[3 * qt + qk] = (unsigned char)(pfwd == qfwd);
            i = j;
        }
    free(at);
    return st;
}

pd_status pd_mesh_orient(pd_mesh *mesh, int *nflipped, pd_diag *diag)
{
    return pd_mesh_orient_cancel(mesh, nflipped, NULL, diag);
}

pd_status pd_mesh_orient_cancel(pd_mesh *mesh, int *nflipped, pd_cancel_flag *cancel, pd_diag *diag)
{
    unsigned polls = 0;
    pd_status st = pd_mesh_validate(mesh, "orient", diag);
    if (st != PD_OK)
        return st;
    int n = mesh->ntris;
    size_t n3 = 3 * (size_t)n + 1, n1 = (size_t)n + 1;
    half_edge *he = malloc(sizeof *he * n3);
    int *nbr = malloc(sizeof *nbr * n3);
    unsigned char *same = malloc(n3);
    unsigned char *flip = calloc(n1, 1);
    int *comp = malloc(sizeof *comp * n1);
    int *list = malloc(sizeof *list * n1); /* BFS queue, and afterwards each component's triangles */
    component *comps = NULL;
    unsigned char *comp_flip = NULL;
    if (!he || !nbr || !same || !flip || !comp || !list) {
        st = pd_fail(diag, PD_ERR_NOMEM, "orient: out of memory for %d triangles", n);
        goto done;
    }
    st = pair_edges(mesh, he, nbr, same, cancel, diag);
    if (st != PD_OK)
        goto done;

    /* Step 2: BFS per component; list[] fills component after component. */
    int ncomps = 0, nlist = 0, ndegenerate = 0;
    for (int t = 0; t < n; t++)
        comp[t] = -1;
    for (int seed = 0; seed < n; seed++) {
        if (tri_degenerate(mesh->tris[seed])) {
            ndegenerate++;
            continue;
        }
        if (comp[seed] >= 0)
            continue;
        comp[seed] = ncomps;
        list[nlist++] = seed;
        for (int head = nlist - 1; head < nlist; head++) {
            if (poll_cancel(cancel, &polls)) {
                st = PD_ERR_CANCELLED;
                goto done;
            }
            int t = list[head];
            for (int k = 0; k < 3; k++) {
                int u = nbr[3 * t + k];
                unsigned char want = flip[t] ^ same[3 * t + k];
                if (comp[u] < 0) {
                    comp[u] = ncomps;
                    flip[u] = want;
                    list[nlist++] = u;
                } else if (flip[u] != want) {
                    st = pd_fail(diag, PD_ERR_ORIENTATION,
                                 "orient: triangles %d and %d across edge (%d, %d) cannot be made to "
                                 "agree: the surface is non-orientable (Moebius-like)",
                                 t, u, mesh->tris[t][k], mesh->tris[t][(k + 1) % 3]);
                    goto done;
                }
            }
        }
        ncomps++;
    }

    /* Step 3: signed volume and bounding box of each component. */
    comps = calloc((size_t)ncomps + 1, sizeof *comps);
    comp_flip = calloc((size_t)ncomps + 1, 1);
    if (!comps || !comp_flip) {
        st = pd_fail(diag, PD_ERR_NOMEM, "orient: out of memory for %d components", ncomps);
        goto done;
    }
    for (int i = 0, c = -1; i < nlist; i++) {
        if (poll_cancel(cancel, &polls)) {
            st = PD_ERR_CANCELLED;
            goto done;
        }
        int t = list[i];
        if (comp[t] != c) {
            c = comp[t];
            comps[c].start = i;
            comps[c].lo = comps[c].hi = mesh->verts[mesh->tris[t][0]];
        }
        comps[c].count++;
        /* Tetrahedra from the component's first vertex: only the sign of the
         * sum is needed, and a nearby apex keeps it free of cancellation. */
        pd_vec3 r = mesh->verts[mesh->tris[list[comps[c].start]][0]];
        pd_vec3 a = v3_sub(mesh->verts[corner(mesh, t, flip[t], 0)], r);
        pd_vec3 b = v3_sub(mesh->verts[corner(mesh, t, flip[t], 1)], r);
        pd_vec3 d = v3_sub(mesh->verts[corner(mesh, t, flip[t], 2)], r);
        comps[c].vol6 += v3_dot(a, v3_cross(b, d));
        for (int k = 0; k < 3; k++) {
            pd_vec3 v = mesh->verts[mesh->tris[t][k]];
            comps[c].lo = v3_min(comps[c].lo, v);
            comps[c].hi = v3_max(comps[c].hi, v);
        }
    }
    for (int c = 0; c < ncomps; c++) {
        /* Each nesting test is a pass over the other components. */
        if (cancel && atomic_load_explicit(cancel, memory_order_relaxed)) {
            st = PD_ERR_CANCELLED;
            goto done;
        }
        if (comps[c].vol6 == 0.0)
            continue; /* flat: no sign to fix; pd_mass_compute will refuse it if alone */
        int outer = ncomps == 1 || nesting_depth(mesh, comps, ncomps, c, list, flip) % 2 == 0;
        comp_flip[c] = (unsigned char)((comps[c].vol6 > 0.0) != outer);
    }

    /* All checks passed: now, and only now, change the mesh. */
    int count = 0;
    for (int t = 0; t < n; t++) {
        if (comp[t] < 0 || !(flip[t] ^ comp_flip[comp[t]]))
            continue;
        int tmp = mesh->tris[t][1];
        mesh->tris[t][1] = mesh->tris[t][2];
        mesh->tris[t][2] = tmp;
        count++;
    }
    if (ndegenerate)
        pd_warn(diag, "orient: %d degenerate triangle%s (repeated vertex) ignored", ndegenerate,
                ndegenerate == 1 ? "" : "s");
    if (nflipped)
        *nflipped = count;
    st = PD_OK;
done:
    free(he);
    free(nbr);
    free(same);
    free(flip);
    free(comp);
    free(list);
    free(comps);
    free(comp_flip);
    return st;
}
