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
#include <string.h>
#include "base/mat3.h"
#include "base/predicates.h"
#include "base/vec3.h"
#include "mesh/mesh_internal.h"
#include "mesh/mesh_tol.h"

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

typedef struct search {
    const pd_mesh *m;
    int *up;        /* flat patches */
    double pad;     /* widening of every projection (PD_SELFX_PAD_REL) */
    size_t tested;  /* pairs given to the exact test */
    int ta, tb;
    pd_vec3 at;
} search;

/* The exact test of triangles a and b (not of one flat patch); records them
 * when they cross. */
static int test_pair(search *s, int a, int b)
{
    if (root(s->up, a) == root(s->up, b))
        return 0;
    const int *A = s->m->tris[a], *B = s->m->tris[b];
    const pd_vec3 *v = s->m->verts;
    const pd_vec3 *p[3] = {&v[A[0]], &v[A[1]], &v[A[2]]};
    const pd_vec3 *q[3] = {&v[B[0]], &v[B[1]], &v[B[2]]};
    s->tested++;
    if (!cross(p, q, &s->at))
        return 0;
    s->ta = a < b ? a : b;
    s->tb = a < b ? b : a;
    return 1;
}

/* Pairs that share one vertex.
 *
 * Two triangles with one common vertex v cross only along a chord of each
 * that starts at v (both planes contain v, and each triangle straddles the
 * other's plane with v on it), so they cross only if some direction from v
 * points into both: the arcs their corners at v cut from the unit sphere
 * about v meet. Each arc lies in the triangle of its two end directions u, w
 * and of the point (u + w) / (1 + u.w) where the arc's end tangents meet;
 * the boxes of those triangles, swept per vertex, pass each pair whose arcs
 * may meet to the exact test. A fan of thin triangles about one corner (a
 * polygon's cap) then costs the pairs of neighbouring arcs, not every pair
 * of the fan, whose boxes in space all hold the corner. */
typedef struct arc {
    double lo[3], hi[3], key; /* key: lo along the sweep's axis */
    int t;
} arc;

static int arc_cmp(const void *pa, const void *pb)
{
    const arc *a = pa, *b = pb;
    if (a->key != b->key)
        return a->key < b->key ? -1 : 1;
    return (a->t > b->t) - (a->t < b->t);
}

static void arc_box(const pd_mesh *m, int t, int v, arc *b)
{
    const int *T = m->tris[t];
    int k = T[0] == v ? 0 : T[1] == v ? 1 : 2;
    pd_vec3 o = m->verts[v];
    pd_vec3 u = v3_unit(v3_sub(m->verts[T[(k + 1) % 3]], o));
    pd_vec3 w = v3_unit(v3_sub(m->verts[T[(k + 2) % 3]], o));
    double c = v3_dot(u, w);
    b->t = t;
    /* Beyond 120 degrees (or a corner of no length) the tangents' meeting
     * point runs off: the whole sphere. */
    if (!(c >= -0.5) || v3_dot(u, u) == 0.0 || v3_dot(w, w) == 0.0) {
        for (int i = 0; i < 3; i++) {
            b->lo[i] = -1.0 - PD_SELFX_ARC_PAD;
            b->hi[i] = 1.0 + PD_SELFX_ARC_PAD;
        }
        return;
    }
    pd_vec3 tip = v3_scale(v3_add(u, w), 1.0 / (1.0 + c));
    double p[3][3] = {{u.x, u.y, u.z}, {w.x, w.y, w.z}, {tip.x, tip.y, tip.z}};
    for (int i = 0; i < 3; i++) {
        b->lo[i] = fmin(fmin(p[0][i], p[1][i]), p[2][i]) - PD_SELFX_ARC_PAD;
        b->hi[i] = fmax(fmax(p[0][i], p[1][i]), p[2][i]) + PD_SELFX_ARC_PAD;
    }
}

/* Sort and sweep of n boxes along the axis where they are shortest against
 * their spread; each pair whose boxes meet and that shares no edge goes to
 * the exact test. 1 when a crossing is found. */
static int sweep(search *s, arc *bx, int n)
{
    int ax = 0;
    double best = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        double lo = HUGE_VAL, hi = -HUGE_VAL, ext = 0.0;
        for (int i = 0; i < n; i++) {
            lo = fmin(lo, bx[i].lo[k]);
            hi = fmax(hi, bx[i].hi[k]);
            ext += bx[i].hi[k] - bx[i].lo[k];
        }
        double r = hi > lo ? ext / (hi - lo) : HUGE_VAL;
        if (r < best) {
            best = r;
            ax = k;
        }
    }
    for (int i = 0; i < n; i++)
        bx[i].key = bx[i].lo[ax];
    qsort(bx, (size_t)n, sizeof *bx, arc_cmp);
    for (int a = 0; a < n; a++)
        for (int b = a + 1; b < n && bx[b].key <= bx[a].hi[ax]; b++) {
            if (bx[b].lo[0] > bx[a].hi[0] || bx[b].hi[0] < bx[a].lo[0] ||
                bx[b].lo[1] > bx[a].hi[1] || bx[b].hi[1] < bx[a].lo[1] ||
                bx[b].lo[2] > bx[a].hi[2] || bx[b].hi[2] < bx[a].lo[2])
                continue;
            if (shared(s->m->tris[bx[a].t], s->m->tris[bx[b].t]) < 2 &&
                test_pair(s, bx[a].t, bx[b].t))
                return 1;
        }
    return 0;
}

/* Every pair that shares exactly one vertex, by the star of each vertex.
 * 1 when a crossing is found, -1 when out of memory. */
static int star_pairs(search *s)
{
    const pd_mesh *m = s->m;
    int nv = m->nverts, found = 0;
    size_t n3 = 3 * (size_t)m->ntris;
    int *start = calloc((size_t)nv + 1, sizeof *start), *list = malloc(sizeof *list * n3);
    arc *bx = malloc(sizeof *bx * n3);
    if (!start || !list || !bx) {
        free(start);
        free(list);
        free(bx);
        return -1;
    }
    for (int t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++)
            start[m->tris[t][k] + 1]++;
    for (int v = 0; v < nv; v++)
        start[v + 1] += start[v];
    /* Filled from the end of each vertex's range, which leaves start[v + 1]
     * at the start of v's range: the ranges shift down by one. */
    for (int t = m->ntris - 1; t >= 0; t--)
        for (int k = 2; k >= 0; k--)
            list[--start[m->tris[t][k] + 1]] = t;
    memmove(start, start + 1, sizeof *start * (size_t)nv);
    start[nv] = (int)n3;
    for (int v = 0; v < nv && !found; v++) {
        int n = start[v + 1] - start[v];
        for (int i = 0; i < n; i++)
            arc_box(m, list[start[v] + i], v, &bx[i]);
        found = sweep(s, bx, n);
    }
    free(start);
    free(list);
    free(bx);
    return found;
}

/* Pairs that share no vertex: a tree of bounding boxes, each oriented along
 * the principal axes of the corners it bounds (one triangle's along its
 * longest edge and its normal) and also kept along the coordinate axes
 * (tried first: cheap and exact). Boxes along the coordinate axes alone do
 * not separate long thin triangles that lie across the axes (a rod turned
 * off them: every pair of its side slivers' boxes meets); oriented ones do.
 * Two boxes are apart when their projections on one of their six axes are
 * apart, a triangle projecting its corners and a box its centre and
 * half-widths; every projection is widened by pad, far above the round-off
 * of the frames and dot products, so a pair that may cross is never
 * dropped: the exact test decides. A node's corners common to all its
 * triangles, and its flat patch, skip a pair of nodes whose triangles all
 * share a vertex (taken by the stars) or a plane. */
typedef struct obox {
    pd_vec3 ax[3];
    double lo[3], hi[3];   /* the corners' projections on ax, widened by pad */
    double blo[3], bhi[3]; /* and on the coordinate axes */
} obox;

/* Triangles per leaf: its pairs, and those with another leaf, are taken
 * triangle by triangle; fewer nodes to visit than with one per leaf. */
enum { LEAF_TRIS = 4 };

typedef struct node {
    obox box;
    int first, count;     /* its triangles: order[first .. first + count) */
    int left, right;      /* children; left < 0 for a leaf */
    int cv[3], ncv;       /* corners common to all its triangles */
    int patch;            /* the flat patch of all its triangles, or -1 */
} node;

typedef struct keyed {
    double key;
    int t;
} keyed;

typedef struct tree {
    node *nodes;
    int nn, *order;
    pd_vec3 *cen; /* centroids, times 3 */
    keyed *tmp;
    obox *tbox;   /* each triangle's own box */
} tree;

static int keyed_less(const keyed *a, const keyed *b)
{
    return a->key < b->key || (a->key == b->key && a->t < b->t);
}

/* Reorders k[0 .. n) so that k[h] is the one a sort would put there, those
 * before it not after it and those after not before (Hoare's selection):
 * linear on average, where a sort at every level of the tree costs a log
 * more. */
static void select_nth(keyed *k, int n, int h)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        /* The median of three as pivot, against sorted or mirrored input. */
        if (keyed_less(&k[mid], &k[lo])) {
            keyed t = k[mid]; k[mid] = k[lo]; k[lo] = t;
        }
        if (keyed_less(&k[hi], &k[lo])) {
            keyed t = k[hi]; k[hi] = k[lo]; k[lo] = t;
        }
        if (keyed_less(&k[hi], &k[mid])) {
            keyed t = k[hi]; k[hi] = k[mid]; k[mid] = t;
        }
        keyed pivot = k[mid];
        int i = lo, j = hi;
        while (i <= j) {
            while (keyed_less(&k[i], &pivot))
                i++;
            while (keyed_less(&pivot, &k[j]))
                j--;
            if (i <= j) {
                keyed t = k[i]; k[i] = k[j]; k[j] = t;
                i++;
                j--;
            }
        }
        if (h <= j)
            hi = j;
        else if (h >= i)
            lo = i;
        else
            return;
    }
}

/* An orthonormal frame (to round-off) with ax[0] along d, ax[1] in the
 * plane of d and e; the coordinate axes when d and e do not span a plane. */
static void frame(pd_vec3 ax[3], pd_vec3 d, pd_vec3 e)
{
    pd_vec3 a = v3_unit(d), b = v3_sub(e, v3_scale(a, v3_dot(a, e)));
    b = v3_unit(b);
    if (v3_dot(a, a) == 0.0 || v3_dot(b, b) == 0.0 || !v3_isfinite(a) || !v3_isfinite(b)) {
        ax[0] = v3(1, 0, 0);
        ax[1] = v3(0, 1, 0);
        ax[2] = v3(0, 0, 1);
        return;
    }
    ax[0] = a;
    ax[1] = v3_unit(v3_sub(b, v3_scale(a, v3_dot(a, b))));
    ax[2] = v3_cross(ax[0], ax[1]);
}

/* The box of triangles ts[0 .. n): one along its longest edge and normal,
 * several along the principal axes of their corners. */
static void fit(const search *s, const tree *tr, const int *ts, int n, obox *b)
{
    const pd_mesh *m = s->m;
    if (n == 1) {
        const int *T = m->tris[ts[0]];
        pd_vec3 e[3];
        int l = 0;
        for (int k = 0; k < 3; k++) {
            e[k] = v3_sub(m->verts[T[(k + 1) % 3]], m->verts[T[k]]);
            if (v3_dot(e[k], e[k]) > v3_dot(e[l], e[l]))
                l = k;
        }
        frame(b->ax, e[l], e[(l + 1) % 3]);
    } else {
        pd_vec3 mean = v3(0, 0, 0);
        for (int i = 0; i < n; i++)
            mean = v3_add(mean, tr->cen[ts[i]]);
        mean = v3_scale(mean, 1.0 / (3.0 * n));
        double C[3][3] = {{0}}, ev[3], V[3][3];
        for (int i = 0; i < n; i++)
            for (int k = 0; k < 3; k++) {
                pd_vec3 d = v3_sub(m->verts[m->tris[ts[i]][k]], mean);
                double x[3] = {d.x, d.y, d.z};
                for (int r = 0; r < 3; r++)
                    for (int c = 0; c < 3; c++)
                        C[r][c] += x[r] * x[c];
            }
        pd_sym_eigen3(CONST_M3(C), ev, V);
        frame(b->ax, v3(V[0][2], V[1][2], V[2][2]), v3(V[0][1], V[1][1], V[2][1]));
    }
    for (int k = 0; k < 3; k++) {
        b->lo[k] = b->blo[k] = HUGE_VAL;
        b->hi[k] = b->bhi[k] = -HUGE_VAL;
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < 3; j++) {
            pd_vec3 p = m->verts[m->tris[ts[i]][j]];
            double c[3] = {p.x, p.y, p.z};
            for (int k = 0; k < 3; k++) {
                double x = v3_dot(b->ax[k], p);
                b->lo[k] = fmin(b->lo[k], x);
                b->hi[k] = fmax(b->hi[k], x);
                b->blo[k] = fmin(b->blo[k], c[k]);
                b->bhi[k] = fmax(b->bhi[k], c[k]);
            }
        }
    for (int k = 0; k < 3; k++) {
        b->lo[k] -= s->pad;
        b->hi[k] += s->pad;
    }
}

/* Builds the node over order[first .. first + count), split at the median
 * of the centroids along the axis of their widest spread; returns its
 * index. */
static int build(search *s, tree *tr, int first, int count)
{
    const pd_mesh *m = s->m;
    int id = tr->nn++, *ts = tr->order + first;
    node *nd = &tr->nodes[id];
    nd->first = first;
    nd->count = count;
    fit(s, tr, ts, count, &nd->box);
    if (count <= LEAF_TRIS) {
        nd->left = nd->right = -1;
        nd->ncv = 0;
        for (int k = 0; k < 3; k++) {
            int v = m->tris[ts[0]][k], all = 1;
            for (int i = 1; i < count && all; i++)
                all = m->tris[ts[i]][0] == v || m->tris[ts[i]][1] == v || m->tris[ts[i]][2] == v;
            if (all)
                nd->cv[nd->ncv++] = v;
        }
        nd->patch = root(s->up, ts[0]);
        for (int i = 1; i < count; i++)
            if (root(s->up, ts[i]) != nd->patch)
                nd->patch = -1;
        return id;
    }
    int ax = 0;
    double spread = -1.0;
    for (int k = 0; k < 3; k++) {
        double lo = HUGE_VAL, hi = -HUGE_VAL;
        for (int i = 0; i < count; i++) {
            double x = v3_dot(nd->box.ax[k], tr->cen[ts[i]]);
            lo = fmin(lo, x);
            hi = fmax(hi, x);
        }
        if (hi - lo > spread) {
            spread = hi - lo;
            ax = k;
        }
    }
    for (int i = 0; i < count; i++)
        tr->tmp[i] = (keyed){v3_dot(nd->box.ax[ax], tr->cen[ts[i]]), ts[i]};
    int half = count / 2;
    select_nth(tr->tmp, count, half);
    for (int i = 0; i < count; i++)
        ts[i] = tr->tmp[i].t;
    int l = build(s, tr, first, half), r = build(s, tr, first + half, count - half);
    nd = &tr->nodes[id];
    const node *L = &tr->nodes[l], *R = &tr->nodes[r];
    nd->left = l;
    nd->right = r;
    nd->ncv = 0;
    for (int i = 0; i < L->ncv; i++)
        for (int j = 0; j < R->ncv; j++)
            if (L->cv[i] == R->cv[j]) {
                nd->cv[nd->ncv++] = L->cv[i];
                break;
            }
    nd->patch = L->patch == R->patch ? L->patch : -1;
    return id;
}

/* The projection on the unit axis w, widened by pad, of triangle t's
 * corners, or (t < 0) of box b by its centre and half-widths. */
static void project(const search *s, const obox *b, int t, pd_vec3 w, double *lo, double *hi)
{
    if (t >= 0) {
        const int *T = s->m->tris[t];
        *lo = HUGE_VAL;
        *hi = -HUGE_VAL;
        for (int j = 0; j < 3; j++) {
            double x = v3_dot(w, s->m->verts[T[j]]);
            *lo = fmin(*lo, x);
            *hi = fmax(*hi, x);
        }
    } else {
        double c = 0.0, r = 0.0;
        for (int k = 0; k < 3; k++) {
            double wk = v3_dot(w, b->ax[k]);
            c += 0.5 * (b->lo[k] + b->hi[k]) * wk;
            r += 0.5 * (b->hi[k] - b->lo[k]) * fabs(wk);
        }
        *lo = c - r;
        *hi = c + r;
    }
    *lo -= s->pad;
    *hi += s->pad;
}

/* Are boxes a and b (each of triangle ta or tb, or of a node when < 0)
 * apart? */
static int apart(const search *s, const obox *a, int ta, const obox *b, int tb)
{
    for (int k = 0; k < 3; k++)
        if (a->bhi[k] < b->blo[k] || b->bhi[k] < a->blo[k])
            return 1;
    for (int side = 0; side < 2; side++) {
        const obox *x = side ? b : a, *y = side ? a : b;
        int ty = side ? ta : tb;
        for (int k = 0; k < 3; k++) {
            double lo, hi;
            project(s, y, ty, x->ax[k], &lo, &hi);
            if (hi < x->lo[k] || lo > x->hi[k])
                return 1;
        }
    }
    return 0;
}

/* Triangles a and b, sharing no vertex, unless their boxes are apart. */
static int tri_pair(search *s, const tree *tr, int a, int b)
{
    if (shared(s->m->tris[a], s->m->tris[b]) > 0 || apart(s, &tr->tbox[a], a, &tr->tbox[b], b))
        return 0;
    return test_pair(s, a, b);
}

static int common_corner(const node *a, const node *b)
{
    for (int i = 0; i < a->ncv; i++)
        for (int j = 0; j < b->ncv; j++)
            if (a->cv[i] == b->cv[j])
                return 1;
    return 0;
}

static int node_pair(search *s, const tree *tr, int ia, int ib)
{
    const node *a = &tr->nodes[ia], *b = &tr->nodes[ib];
    if (common_corner(a, b) || (a->patch >= 0 && a->patch == b->patch) ||
        apart(s, &a->box, -1, &b->box, -1))
        return 0;
    if (a->left < 0 && b->left < 0) {
        for (int i = 0; i < a->count; i++)
            for (int j = 0; j < b->count; j++)
                if (tri_pair(s, tr, tr->order[a->first + i], tr->order[b->first + j]))
                    return 1;
        return 0;
    }
    if (b->left < 0 || (a->left >= 0 && a->count >= b->count))
        return node_pair(s, tr, a->left, ib) || node_pair(s, tr, a->right, ib);
    return node_pair(s, tr, ia, b->left) || node_pair(s, tr, ia, b->right);
}

static int node_self(search *s, const tree *tr, int id)
{
    const node *nd = &tr->nodes[id];
    if (nd->ncv > 0 || nd->patch >= 0)
        return 0;
    if (nd->left < 0) {
        for (int i = 0; i < nd->count; i++)
            for (int j = i + 1; j < nd->count; j++)
                if (tri_pair(s, tr, tr->order[nd->first + i], tr->order[nd->first + j]))
                    return 1;
        return 0;
    }
    return node_self(s, tr, nd->left) || node_self(s, tr, nd->right) ||
           node_pair(s, tr, nd->left, nd->right);
}

/* 1 when a crossing is found, -1 when out of memory. */
static int apart_pairs(search *s)
{
    const pd_mesh *m = s->m;
    size_t n = (size_t)m->ntris;
    tree tr = {malloc(sizeof *tr.nodes * 2 * n), 0, malloc(sizeof *tr.order * n),
               malloc(sizeof *tr.cen * n), malloc(sizeof *tr.tmp * n), malloc(sizeof *tr.tbox * n)};
    int found = -1;
    if (tr.nodes && tr.order && tr.cen && tr.tmp && tr.tbox) {
        for (int t = 0; t < m->ntris; t++) {
            const int *T = m->tris[t];
            tr.order[t] = t;
            tr.cen[t] = v3_add(v3_add(m->verts[T[0]], m->verts[T[1]]), m->verts[T[2]]);
        }
        for (int t = 0; t < m->ntris; t++)
            fit(s, &tr, &t, 1, &tr.tbox[t]);
        build(s, &tr, 0, m->ntris);
        found = node_self(s, &tr, 0);
    }
    free(tr.nodes);
    free(tr.order);
    free(tr.cen);
    free(tr.tmp);
    free(tr.tbox);
    return found;
}

pd_status pd_mesh_self_crossing(const pd_mesh *m, int *ta, int *tb, pd_vec3 *at, size_t *tested)
{
    *ta = *tb = -1;
    if (tested)
        *tested = 0;
    if (m->ntris < 2)
        return PD_OK;
    int *up = malloc(sizeof *up * (size_t)m->ntris);
    if (!up || flat_patches(m, up) != PD_OK) {
        free(up);
        return PD_ERR_NOMEM;
    }
    double R = 0.0;
    for (int i = 0; i < m->nverts; i++)
        R = fmax(R, fmax(fabs(m->verts[i].x), fmax(fabs(m->verts[i].y), fabs(m->verts[i].z))));
    search s = {m, up, PD_SELFX_PAD_REL * R, 0, -1, -1, {0, 0, 0}};
    int found = star_pairs(&s);
    if (found == 0)
        found = apart_pairs(&s);
    free(up);
    if (tested)
        *tested = s.tested;
    if (found < 0)
        return PD_ERR_NOMEM;
    if (found) {
        *ta = s.ta;
        *tb = s.tb;
        *at = s.at;
    }
    return PD_OK;
}
