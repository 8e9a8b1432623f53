/* mesh_selfx.c: does a welded mesh's surface cross itself?
 *
 * Two closed shells that each pass orientation can still overlap, and a
 * shell can fold through itself; the mass properties then count some volume
 * twice or negatively, which the moment checks of the part build catch only
 * when the excess is large. This finds a pair of triangles whose relative
 * interiors meet transversally. Every decision is a sign of pd_orient3d, so
 * triangles that share a vertex or an edge, or touch at a point or along a
 * segment of their boundaries, are never reported: touching is not
 * crossing. Coplanar pairs are not examined (they touch, or overlap within
 * one plane, which the moment checks see as area, not as volume). */
#include <math.h>
#include <stdlib.h>
#include "base/predicates.h"
#include "base/vec3.h"
#include "mesh/mesh_internal.h"

typedef struct box {
    double lo[3], hi[3], key; /* key: lo along the sweep's axis */
    int t;
} box;

static int box_cmp(const void *pa, const void *pb)
{
    const box *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

/* pd_orient3d, 0 without computing when two of the points are one vertex
 * of the mesh (the same address): triangles that share a vertex would
 * otherwise send every such test to the exact fallback, its determinant
 * being exactly zero. */
static int orient(const pd_vec3 *a, const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d)
{
    if (d == a || d == b || d == c || a == b || a == c || b == c)
        return 0;
    /* Four points with one coordinate equal lie in a plane of that axis,
     * exactly: the usual flat face of a part, fanned into triangles that
     * share a corner and whose boxes all meet, would send every pair to the
     * exact fallback. */
    if ((a->x == b->x && a->x == c->x && a->x == d->x) ||
        (a->y == b->y && a->y == c->y && a->y == d->y) ||
        (a->z == b->z && a->z == c->z && a->z == d->z))
        return 0;
    return pd_orient3d(a, b, c, d);
}

/* Signs of p0, p1, p2 against the plane of q (orient3d(q0, q1, q2, p)),
 * those of q's own vertices (0) first; 0 as soon as the rest cannot give
 * both a positive and a negative sign (the triangle does not straddle the
 * plane), 1 when all three are known. Neighbours on a flat or nearly flat
 * stretch of surface have vertices on each other's planes, whose signs need
 * the exact fallback: stopping at the first such zero saves most of it. */
static int side(const pd_vec3 *const q[3], const pd_vec3 *const p[3], int s[3])
{
    int known[3], pos = 0, neg = 0, left = 3;
    for (int i = 0; i < 3; i++) {
        known[i] = p[i] == q[0] || p[i] == q[1] || p[i] == q[2];
        if (known[i]) {
            s[i] = 0;
            left--;
        }
    }
    for (int i = 0; i < 3; i++) {
        if ((pos == 0) + (neg == 0) > left)
            return 0;
        if (known[i])
            continue;
        s[i] = orient(q[0], q[1], q[2], p[i]);
        pos += s[i] > 0;
        neg += s[i] < 0;
        left--;
    }
    return pos && neg;
}

/* The index of a vertex alone on its strict side of the plane (the other
 * two are on the other side or on the plane), for signs that include both
 * a positive and a negative one. */
static int lone(const int s[3])
{
    for (int i = 0; i < 3; i++)
        if (s[i] != 0 && s[(i + 1) % 3] != s[i] && s[(i + 2) % 3] != s[i])
            return i;
    return -1;
}

/* The point of segment ab on the plane (n, off), rounded. */
static pd_vec3 on_plane(pd_vec3 a, pd_vec3 b, pd_vec3 n, double off)
{
    double da = v3_dot(n, a) - off, db = v3_dot(n, b) - off;
    double t = da == db ? 0.5 : da / (da - db);
    return v3_add(a, v3_scale(v3_sub(b, a), t));
}

/* Do the relative interiors of triangles p and q cross? Both straddle the
 * other's plane strictly; the planes then meet in a line that each triangle
 * cuts in a chord whose interior lies in its interior, and the triangles
 * cross when the open chords overlap. Arranged so that p[0] and q[0] are the
 * lone vertices, each on the positive side of the other's plane, the chords
 * overlap when q's chord starts before p's ends and p's starts before q's
 * ends, two orientation signs (Devillers and Guigue's formulation). On
 * success *at is a point of the overlap. */
static int cross(const pd_vec3 *p[3], const pd_vec3 *q[3], pd_vec3 *at)
{
    int sp[3], sq[3];
    if (!side(q, p, sp) || !side(p, q, sq))
        return 0;
    int i = lone(sp), j = lone(sq);
    if (i < 0 || j < 0)
        return 0;
    const pd_vec3 *P[3] = {p[i], p[(i + 1) % 3], p[(i + 2) % 3]};
    const pd_vec3 *Q[3] = {q[j], q[(j + 1) % 3], q[(j + 2) % 3]};
    /* P[0] on the positive side of q's plane: swapping Q[1] and Q[2] turns
     * that plane over; likewise for Q[0] and p's plane. */
    if (sp[i] < 0) {
        const pd_vec3 *t = Q[1];
        Q[1] = Q[2];
        Q[2] = t;
    }
    if (sq[j] < 0) {
        const pd_vec3 *t = P[1];
        P[1] = P[2];
        P[2] = t;
    }
    if (!(orient(P[0], P[1], Q[0], Q[1]) < 0 && orient(P[0], P[2], Q[2], Q[0]) < 0))
        return 0;
    /* A point of the overlap: the middle two of the chords' four ends along
     * the line, averaged. Rounded; the decision above is exact. */
    pd_vec3 np = v3_cross(v3_sub(*P[1], *P[0]), v3_sub(*P[2], *P[0]));
    pd_vec3 nq = v3_cross(v3_sub(*Q[1], *Q[0]), v3_sub(*Q[2], *Q[0]));
    pd_vec3 dir = v3_cross(np, nq);
    double oq = v3_dot(nq, *Q[0]), op = v3_dot(np, *P[0]);
    pd_vec3 e[4] = {on_plane(*P[0], *P[1], nq, oq), on_plane(*P[0], *P[2], nq, oq),
                    on_plane(*Q[0], *Q[1], np, op), on_plane(*Q[0], *Q[2], np, op)};
    double u[4];
    for (int k = 0; k < 4; k++)
        u[k] = v3_dot(dir, e[k]);
    int a0 = u[0] <= u[1] ? 0 : 1, a1 = 1 - a0, b0 = u[2] <= u[3] ? 2 : 3, b1 = 5 - b0;
    pd_vec3 from = u[a0] >= u[b0] ? e[a0] : e[b0], to = u[a1] <= u[b1] ? e[a1] : e[b1];
    *at = v3_scale(v3_add(from, to), 0.5);
    return 1;
}

/* Is triangle t's area zero, exactly? Its corners are collinear when their
 * projections on all three coordinate planes are; each projection's
 * orientation is that of orient3d with the points flattened onto the plane
 * and the fourth raised by 1 above the first (exact: the lift and the zeros
 * add no rounding). */
static int degenerate(const pd_mesh *m, int t)
{
    const pd_vec3 *v[3] = {&m->verts[m->tris[t][0]], &m->verts[m->tris[t][1]],
                           &m->verts[m->tris[t][2]]};
    for (int k = 0; k < 3; k++) {
        pd_vec3 f[3];
        for (int i = 0; i < 3; i++)
            f[i] = k == 0 ? v3(v[i]->y, v[i]->z, 0) : k == 1 ? v3(v[i]->z, v[i]->x, 0)
                                                             : v3(v[i]->x, v[i]->y, 0);
        pd_vec3 up = v3(f[0].x, f[0].y, 1.0);
        if (pd_orient3d(&f[0], &f[1], &f[2], &up) != 0)
            return 0;
    }
    return 1;
}

static int root(int *up, int t)
{
    while (up[t] != t)
        t = up[t] = up[up[t]];
    return t;
}

typedef struct edge {
    int a, b, t;
} edge;

static int edge_cmp(const void *pa, const void *pb)
{
    const edge *x = pa, *y = pb;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    if (x->b != y->b)
        return x->b < y->b ? -1 : 1;
    return (x->t > y->t) - (x->t < y->t);
}

/* Flat patches: triangles joined through shared edges to neighbours in
 * their plane, exactly (neither of the two degenerate, the fourth corner on
 * the plane of the other three); *up[t] names t's patch. Two triangles of
 * one patch lie in one plane (each step keeps the plane: two corners of the
 * edge and a third not on their line), and coplanar pairs are never found
 * crossing, so the sweep skips them: a flat face fanned into many triangles
 * about one corner would otherwise test every pair of them, each sign an
 * exact zero. */
static pd_status flat_patches(const pd_mesh *m, int *up)
{
    size_t ne = 3 * (size_t)m->ntris;
    edge *e = malloc(sizeof *e * ne);
    char *flat = malloc((size_t)m->ntris);
    if (!e || !flat) {
        free(e);
        free(flat);
        return PD_ERR_NOMEM;
    }
    for (int t = 0; t < m->ntris; t++) {
        up[t] = t;
        flat[t] = !degenerate(m, t);
        for (int k = 0; k < 3; k++) {
            int a = m->tris[t][k], b = m->tris[t][(k + 1) % 3];
            e[3 * (size_t)t + (size_t)k] = (edge){a < b ? a : b, a < b ? b : a, t};
        }
    }
    qsort(e, ne, sizeof *e, edge_cmp);
    for (size_t i = 0; i + 1 < ne; i++) {
        const edge *x = &e[i], *y = &e[i + 1];
        if (x->a != y->a || x->b != y->b || !flat[x->t] || !flat[y->t])
            continue;
        int c = -1, d = -1;
        for (int k = 0; k < 3; k++) {
            int vx = m->tris[x->t][k], vy = m->tris[y->t][k];
            if (vx != x->a && vx != x->b)
                c = vx;
            if (vy != x->a && vy != x->b)
                d = vy;
        }
        if (c < 0 || d < 0 || c == d)
            continue;
        if (orient(&m->verts[x->a], &m->verts[x->b], &m->verts[c], &m->verts[d]) == 0) {
            int rx = root(up, x->t), ry = root(up, y->t);
            up[rx > ry ? rx : ry] = rx > ry ? ry : rx;
        }
    }
    free(e);
    free(flat);
    return PD_OK;
}

static int shared(const int a[3], const int b[3])
{
    int n = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            n += a[i] == b[j];
    return n;
}

pd_status pd_mesh_self_crossing(const pd_mesh *m, int *ta, int *tb, pd_vec3 *at)
{
    *ta = *tb = -1;
    if (m->ntris < 2)
        return PD_OK;
    box *bx = malloc(sizeof *bx * (size_t)m->ntris);
    int *up = malloc(sizeof *up * (size_t)m->ntris);
    if (!bx || !up || flat_patches(m, up) != PD_OK) {
        free(bx);
        free(up);
        return PD_ERR_NOMEM;
    }
    for (int t = 0; t < m->ntris; t++) {
        const pd_vec3 *v[3] = {&m->verts[m->tris[t][0]], &m->verts[m->tris[t][1]],
                               &m->verts[m->tris[t][2]]};
        double c[3][3] = {{v[0]->x, v[0]->y, v[0]->z}, {v[1]->x, v[1]->y, v[1]->z},
                          {v[2]->x, v[2]->y, v[2]->z}};
        for (int k = 0; k < 3; k++) {
            bx[t].lo[k] = fmin(fmin(c[0][k], c[1][k]), c[2][k]);
            bx[t].hi[k] = fmax(fmax(c[0][k], c[1][k]), c[2][k]);
        }
        bx[t].t = t;
    }
    /* Sort and sweep along one axis: each triangle meets only those whose
     * range along it starts within its own; the other two ranges then prune
     * before the exact test. The axis is the one along which the triangles'
     * ranges are shortest against the mesh's (the pairs the sweep visits go
     * as their ratio): a part long along x made of long triangles is swept
     * across. The first crossing pair in sweep order is the one reported. */
    int ax = 0;
    double best = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        double lo = HUGE_VAL, hi = -HUGE_VAL, ext = 0.0;
        for (int t = 0; t < m->ntris; t++) {
            lo = fmin(lo, bx[t].lo[k]);
            hi = fmax(hi, bx[t].hi[k]);
            ext += bx[t].hi[k] - bx[t].lo[k];
        }
        double r = hi > lo ? ext / (hi - lo) : HUGE_VAL;
        if (r < best) {
            best = r;
            ax = k;
        }
    }
    for (int t = 0; t < m->ntris; t++)
        bx[t].key = bx[t].lo[ax];
    qsort(bx, (size_t)m->ntris, sizeof *bx, box_cmp);
    for (int a = 0; a < m->ntris && *ta < 0; a++) {
        for (int b = a + 1; b < m->ntris && bx[b].key <= bx[a].hi[ax]; b++) {
            if (bx[b].lo[0] > bx[a].hi[0] || bx[b].hi[0] < bx[a].lo[0] ||
                bx[b].lo[1] > bx[a].hi[1] || bx[b].hi[1] < bx[a].lo[1] ||
                bx[b].lo[2] > bx[a].hi[2] || bx[b].hi[2] < bx[a].lo[2])
                continue;
            const int *A = m->tris[bx[a].t], *B = m->tris[bx[b].t];
            if (shared(A, B) >= 2 || root(up, bx[a].t) == root(up, bx[b].t))
                continue;
            const pd_vec3 *p[3] = {&m->verts[A[0]], &m->verts[A[1]], &m->verts[A[2]]};
            const pd_vec3 *q[3] = {&m->verts[B[0]], &m->verts[B[1]], &m->verts[B[2]]};
            if (cross(p, q, at)) {
                *ta = bx[a].t < bx[b].t ? bx[a].t : bx[b].t;
                *tb = bx[a].t < bx[b].t ? bx[b].t : bx[a].t;
                break;
            }
        }
    }
    free(bx);
    free(up);
    return PD_OK;
}
