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
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base/lp.h"
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

/* The search's boxes hold finite numbers only (the mesh's coordinates are
 * finite), so the comparisons below are min and max, inline where libm's
 * fmin and fmax, which also order NaNs, are calls through the PLT. */
static inline double dmin(double a, double b)
{
    return a < b ? a : b;
}

static inline double dmax(double a, double b)
{
    return a > b ? a : b;
}

/* How many steps of a long loop run between two reads of the cancel flag:
 * each step is at most a few microseconds, so a few thousand of them keep a
 * cancelled search's answer within a millisecond or so. */
enum { POLL_EVERY = 4096 };

typedef struct search {
    const pd_mesh *m;
    int *patch;            /* the flat patch of each triangle */
    int *start, *list;     /* the triangles about vertex v: list[start[v] .. start[v + 1]) */
    double pad;            /* widening of every projection (PD_SELFX_PAD_REL) */
    float *plane;          /* per triangle: normal and rejection bound (plane_of) */
    size_t tested;         /* pairs past the broad phase (the plane filter's input) */
    int ta, tb;
    pd_vec3 at;
    pd_cancel_flag *cancel; /* may be NULL */
    unsigned polls;
    int cancelled;
} search;

/* 1 when the caller's flag says stop (read every POLL_EVERY calls). */
static int stop(search *s)
{
    if (s->cancelled)
        return 1;
    if (!s->cancel || ++s->polls % POLL_EVERY)
        return 0;
    s->cancelled = atomic_load_explicit(s->cancel, memory_order_relaxed) != 0;
    return s->cancelled;
}

static int root(int *up, int t)
{
    while (up[t] != t)
        t = up[t] = up[up[t]];
    return t;
}

/* The triangles about each vertex, in increasing order of triangle. */
static int build_stars(search *s)
{
    const pd_mesh *m = s->m;
    int nv = m->nverts;
    size_t n3 = 3 * (size_t)m->ntris;
    s->start = calloc((size_t)nv + 1, sizeof *s->start);
    s->list = malloc(sizeof *s->list * n3);
    if (!s->start || !s->list)
        return -1;
    for (int t = 0; t < m->ntris; t++)
        for (int k = 0; k < 3; k++)
            s->start[m->tris[t][k] + 1]++;
    for (int v = 0; v < nv; v++)
        s->start[v + 1] += s->start[v];
    /* Filled from the end of each vertex's range, which leaves start[v + 1]
     * at the start of v's range: the ranges shift down by one. */
    for (int t = m->ntris - 1; t >= 0; t--)
        for (int k = 2; k >= 0; k--)
            s->list[--s->start[m->tris[t][k] + 1]] = t;
    memmove(s->start, s->start + 1, sizeof *s->start * (size_t)nv);
    s->start[nv] = (int)n3;
    return 0;
}

/* A sufficient condition for no crossing, checked in linear time before the
 * search: the surface is closed and consistently oriented (every directed
 * edge once, its reverse once), every triangle faces one point o strictly
 * from the same side (orient3d(a, b, c, o) all of one sign, none zero), and
 * a line through o pierces exactly two triangles, through their interiors.
 *
 * Why it suffices. Project the surface from o onto the sphere about o. Each
 * triangle maps one to one onto a spherical triangle (o is off its plane),
 * all with the same orientation; the surface being a closed cycle (each
 * edge's two triangles run it in opposite directions), the number of
 * triangles a ray from o meets through their interiors is the same for
 * every ray that misses all edges: the degree of the projection. The line's
 * two rays, which miss every edge (no zero sign below), meet two triangles
 * in all, so that degree is 1. If two triangles crossed, a point x of both
 * relative interiors would have a neighbourhood of rays from o, all meeting
 * both triangles near x (each projects its interior onto an open set); one
 * of them misses every edge and meets two triangles, against a degree of 1.
 * A star-shaped part (a ball, a noisy scan of one, a rod, a die) passes;
 * any other fails one of the signs or the count, usually early, and the
 * search below decides. The point o comes from kernel_point. */
static int faces_point(const pd_mesh *m, search *s, pd_vec3 o)
{
    const pd_vec3 *v = m->verts;
    int sign = 0;
    for (int t = 0; t < m->ntris; t++) {
        const int *T = m->tris[t];
        int g = pd_orient3d(&v[T[0]], &v[T[1]], &v[T[2]], &o);
        if (g == 0 || (sign != 0 && g != sign) || stop(s))
            return 0;
        sign = g;
    }
    return 1;
}

/* Twice the degree of the projection from o: the triangles the line
 * through o and p pierces through their interiors (both rays), the
 * front-facing ones less the back-facing ones (every one counts 1 when
 * side is NULL); LONG_MIN when the line touches an edge or a corner of
 * one, or a grazing triangle. */
static long line_degree(const pd_mesh *m, pd_vec3 o, pd_vec3 p, const signed char *side, int front)
{
    const pd_vec3 *v = m->verts;
    long sum = 0;
    for (int u = 0; u < m->ntris; u++) {
        const int *U = m->tris[u];
        int g0 = pd_orient3d(&o, &p, &v[U[0]], &v[U[1]]);
        int g1 = pd_orient3d(&o, &p, &v[U[1]], &v[U[2]]);
        if (g0 * g1 < 0)
            continue;
        int g2 = pd_orient3d(&o, &p, &v[U[2]], &v[U[0]]);
        if (g0 * g2 < 0 || g1 * g2 < 0)
            continue;
        if (g0 == 0 || g1 == 0 || g2 == 0 || (side && side[u] == 0))
            return LONG_MIN;
        sum += !side || side[u] == front ? 1 : -1;
    }
    return sum;
}

static int int_cmp(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Sorts a vertex's few neighbours by insertion, a fan's many by qsort. */
static void sort_ints(int *x, int n)
{
    if (n > 24) {
        qsort(x, (size_t)n, sizeof *x, int_cmp);
        return;
    }
    for (int i = 1; i < n; i++) {
        int y = x[i], j = i;
        for (; j > 0 && x[j - 1] > y; j--)
            x[j] = x[j - 1];
        x[j] = y;
    }
}

/* Every directed edge once and its reverse once: at each vertex, the
 * corners that follow it in its triangles are distinct and are those that
 * precede it. 1 when so, 0 when not, -1 when out of memory. */
static int closed_oriented(search *s)
{
    const pd_mesh *m = s->m;
    int maxdeg = 0, ok = 1;
    for (int v = 0; v < m->nverts; v++)
        maxdeg = s->start[v + 1] - s->start[v] > maxdeg ? s->start[v + 1] - s->start[v] : maxdeg;
    int *out = malloc(sizeof *out * (2 * (size_t)maxdeg + 1)), *in = out + maxdeg;
    if (!out)
        return -1;
    for (int a = 0; a < m->nverts && ok && !stop(s); a++) {
        int n = s->start[a + 1] - s->start[a];
        for (int i = 0; i < n; i++) {
            const int *T = m->tris[s->list[s->start[a] + i]];
            int k = T[0] == a ? 0 : T[1] == a ? 1 : 2;
            out[i] = T[(k + 1) % 3];
            in[i] = T[(k + 2) % 3];
        }
        sort_ints(out, n);
        sort_ints(in, n);
        for (int i = 0; i < n && ok; i++)
            ok = out[i] == in[i] && (i == 0 || out[i] != out[i - 1]);
    }
    free(out);
    return ok && !s->cancelled;
}

/* Triangle t's plane as a constraint of the kernel's program: u . x + r
 * <= u . (a - c0), u its unit normal turned by sg towards the outside, a a
 * corner, x the point measured from c0 and r its distance inside the
 * plane. 0 for a triangle of no area. */
static int kernel_row(const pd_mesh *m, int t, int sg, pd_vec3 c0, pd_lp_halfspace *h)
{
    const pd_vec3 *v = m->verts;
    const int *T = m->tris[t];
    pd_vec3 a = v3_sub(v[T[0]], c0);
    pd_vec3 n = v3_cross(v3_sub(v[T[1]], v[T[0]]), v3_sub(v[T[2]], v[T[0]]));
    double len = v3_norm(n);
    if (!(len > 0.0) || !isfinite(len))
        return 0;
    pd_vec3 u = v3_scale(n, sg / len);
    h->a[0] = u.x;
    h->a[1] = u.y;
    h->a[2] = u.z;
    h->a[3] = 1.0;
    h->b = v3_dot(u, a);
    return 1;
}

/* A candidate for o: the centre of the largest ball inside every
 * triangle's plane (the part's kernel, where it has one), by a linear
 * program over a sample of the planes, then again with the planes the last
 * answer violated, until it violates none (Clarkson's scheme: the working
 * set stays small). Floating point: faces_point then decides exactly.
 * Only the triangles t with in[t] count (all when in is NULL). 1 with the
 * point, *exact set when no plane is violated (the kernel's centre), else
 * clear (the last round's answer: the point least outside its sample's
 * planes); 0 when there is none, -1 when out of memory. */
enum { KERNEL_SAMPLE = 1024, KERNEL_ADD = 4096, KERNEL_ROUNDS = 12 };

static int kernel_point(search *s, const unsigned char *in, pd_vec3 *o, int *exact)
{
    const pd_mesh *m = s->m;
    const pd_vec3 *v = m->verts;
    int n = m->ntris;
    double lo[4] = {HUGE_VAL, HUGE_VAL, HUGE_VAL, 0}, hi[4] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL, 0};
    for (int i = 0; i < m->nverts; i++) {
        double c[3] = {v[i].x, v[i].y, v[i].z};
        for (int k = 0; k < 3; k++) {
            lo[k] = dmin(lo[k], c[k]);
            hi[k] = dmax(hi[k], c[k]);
        }
    }
    pd_vec3 c0 = v3(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]));
    double diag = 0.0, vol = 0.0;
    for (int k = 0; k < 3; k++) {
        double e = hi[k] - lo[k];
        diag += e * e;
        lo[k] -= k == 0 ? c0.x : k == 1 ? c0.y : c0.z;
        hi[k] -= k == 0 ? c0.x : k == 1 ? c0.y : c0.z;
    }
    diag = sqrt(diag);
    lo[3] = -diag;
    hi[3] = diag;
    /* Outwards by the sign of the enclosed volume. */
    int nin = 0;
    for (int t = 0; t < n; t++) {
        const int *T = m->tris[t];
        if (in && !in[t])
            continue;
        nin++;
        vol += v3_dot(v3_sub(v[T[0]], c0),
                      v3_cross(v3_sub(v[T[1]], c0), v3_sub(v[T[2]], c0)));
    }
    int sg = vol >= 0.0 ? 1 : -1, cap = 2 * KERNEL_SAMPLE + KERNEL_ROUNDS * KERNEL_ADD, k = 0;
    if (!(diag > 0.0) || !isfinite(diag))
        return 0;
    pd_lp_halfspace *w = malloc(sizeof *w * (size_t)cap);
    if (!w)
        return -1;
    int step = nin > KERNEL_SAMPLE ? nin / KERNEL_SAMPLE : 1, ok = 1;
    for (int t = 0, i = 0; t < n && ok; t++)
        if ((!in || in[t]) && i++ % step == 0)
            ok = kernel_row(m, t, sg, c0, &w[k++]);
    uint64_t seed = 0x9e3779b97f4a7c15u;
    double y[4] = {0, 0, 0, 0}, c[4] = {0, 0, 0, 1};
    int found = 0, solved = 0;
    for (int round = 0; ok && round < KERNEL_ROUNDS && !stop(s); round++) {
        /* A fixed shuffle (Seidel's expected time needs an order unrelated
         * to the planes'). */
        for (int i = k - 1; i > 0; i--) {
            seed = seed * 6364136223846793005u + 1442695040888963407u;
            int r = (int)((seed >> 33) % (uint64_t)(i + 1));
            pd_lp_halfspace x = w[i];
            w[i] = w[r];
            w[r] = x;
        }
        int st = pd_lp_solve(4, w, k, c, lo, hi, PD_SELFX_KERNEL_LP_TOL_REL * diag, y);
        if (st < 0) {
            free(w);
            return -1;
        }
        if (st == 0)
            break;
        solved = 1;
        if (!(y[3] > PD_SELFX_KERNEL_RADIUS_REL * diag))
            break;
        /* The planes this centre is not y[3] inside of: all of them when
         * they are few (one pass), else a stride of them (a second). */
        int bad = 0, added = 0;
        pd_lp_halfspace h;
        for (int pass = 0; pass < 2 && ok; pass++) {
            int every = pass == 0 ? 1 : bad / KERNEL_ADD + 1, seen = 0;
            added = 0;
            for (int t = 0; t < n && ok; t++) {
                if (in && !in[t])
                    continue;
                ok = kernel_row(m, t, sg, c0, &h);
                if (ok && h.a[0] * y[0] + h.a[1] * y[1] + h.a[2] * y[2] +
                                  PD_SELFX_KERNEL_INSIDE_SHARE * y[3] >
                              h.b) {
                    bad += pass == 0;
                    if (seen++ % every == 0 && added < KERNEL_ADD)
                        w[k + added++] = h;
                }
            }
            if (bad <= KERNEL_ADD)
                break;
        }
        k += added;
        if (bad == 0) {
            found = 1;
            break;
        }
        if (k + KERNEL_ADD > cap)
            break;
    }
    free(w);
    if (!ok || !solved)
        return 0;
    *o = v3(c0.x + y[0], c0.y + y[1], c0.z + y[2]);
    *exact = found;
    return 1;
}

/* 1 when the condition above holds (no crossing), 0 when not or not shown,
 * -1 when out of memory. */
static int star_shaped(search *s, int *closed)
{
    const pd_mesh *m = s->m;
    const pd_vec3 *v = m->verts;
    *closed = closed_oriented(s);
    if (*closed != 1)
        return *closed;
    pd_vec3 o;
    int exact = 0, kp = kernel_point(s, NULL, &o, &exact);
    if (kp != 1 || !exact)
        return kp < 0 ? -1 : 0;
    if (!faces_point(m, s, o))
        return 0;
    /* Lines through the centres of the first few triangles: one that
     * grazes an edge is tried again through the next. */
    for (int t = 0; t < m->ntris && t < 8; t++) {
        const int *T = m->tris[t];
        pd_vec3 p = v3_scale(v3_add(v3_add(v[T[0]], v[T[1]]), v[T[2]]), 1.0 / 3.0);
        long h = line_degree(m, o, p, NULL, 1);
        if (h != LONG_MIN)
            return h == 2;
    }
    return 0;
}

/* Parts that are not star-shaped. Take o from kernel_point over the
 * planes of the largest connected part (inside it, or least outside its
 * planes; inside one shell of a part of several) and call a triangle
 * front-facing when o is on the side of its plane that most triangles put
 * it on, back-facing on the other side, grazing in its plane. The count of
 * front-facing triangles a ray from o meets, less the back-facing ones, is
 * the degree of the projection from o (for rays that miss the edges); when
 * a line through o gives 2 for its two rays, that degree is 1, and every
 * ray that meets two front-facing triangles also meets a back-facing one.
 * Two front-facing triangles that cross therefore do so in a direction
 * from o that some back-facing or grazing triangle covers (the rays near a
 * crossing meet both, so each of them meets one of finitely many closed
 * sets of directions, and one of those holds the crossing's direction; a
 * grazing triangle's directions are those of its edges), and a crossing
 * that involves a back-facing or grazing triangle is in a direction it
 * covers too. So the search needs only the back-facing and grazing
 * triangles and the front-facing ones whose directions from o meet
 * theirs: each triangle's directions lie in the cap about the mean of its
 * corners' unit directions that holds them (a cap of chord radius under 1
 * holds the spherical triangle of its corners; a grazing triangle with o
 * inside it or on its boundary gives a radius of at least the square root
 * of 2 or a corner at o, and is kept), caps met by a chord test, widened
 * by PD_SELFX_CAP_PAD (mesh_tol.h).
 * A part that is nearly star-shaped (a scan with a few overhangs) leaves
 * few triangles to the search; on a pair of spheres apart, o in one, the
 * other and the first's triangles that lie in its directions, and with o
 * in the other too (narrow), only the triangles of each that the other
 * hides. */
typedef struct dircap {
    double c[3], r; /* unit centre and chord radius */
} dircap;

/* Triangle t's cap seen from o; 0 when it reaches beyond 60 degrees (or a
 * corner is o). */
static int cap_of(const pd_mesh *m, int t, pd_vec3 o, dircap *x)
{
    const int *T = m->tris[t];
    pd_vec3 u[3], c = v3(0, 0, 0);
    for (int k = 0; k < 3; k++) {
        pd_vec3 d = v3_sub(m->verts[T[k]], o);
        double len = v3_norm(d);
        if (!(len > 0.0) || !isfinite(len))
            return 0;
        u[k] = v3_scale(d, 1.0 / len);
        c = v3_add(c, u[k]);
    }
    double len = v3_norm(c);
    if (!(len > 1e-3))
        return 0;
    c = v3_scale(c, 1.0 / len);
    double r = 0.0;
    for (int k = 0; k < 3; k++)
        r = dmax(r, v3_norm(v3_sub(u[k], c)));
    r = r * (1.0 + PD_SELFX_CAP_ROUND_REL) + PD_SELFX_CAP_PAD;
    if (!(r < 1.0))
        return 0;
    x->c[0] = c.x;
    x->c[1] = c.y;
    x->c[2] = c.z;
    x->r = r;
    return 1;
}

static int caps_meet(const dircap *a, const dircap *b)
{
    double dx = a->c[0] - b->c[0], dy = a->c[1] - b->c[1], dz = a->c[2] - b->c[2];
    double rr = a->r + b->r + PD_SELFX_CAP_PAD;
    return dx * dx + dy * dy + dz * dz <= rr * rr;
}

/* The cells of width h that the boxes of the back-facing and grazing caps
 * meet, as a hash set; a cap over more than CAP_INSERT_CELLS cells is kept
 * in a short list of its own, tested against every front-facing cap. A
 * front-facing cap whose box meets none of the cells, and that meets none
 * of the listed caps, meets no back-facing or grazing cap; one whose box
 * spans more than CAP_CELLS cells is kept without looking. */
enum { CAP_CELLS = 64, CAP_INSERT_CELLS = 512, CAP_BIG = 16 };

typedef struct capgrid {
    double h;
    size_t mask, used;
    uint64_t *key; /* cell key + 1, 0 for an empty slot */
    int big[CAP_BIG], nbig;
} capgrid;

static size_t slot_of(const capgrid *g, uint64_t key)
{
    uint64_t h = key * 0x9e3779b97f4a7c15ULL;
    size_t i = (size_t)(h >> 20) & g->mask;
    while (g->key[i] && g->key[i] != key + 1)
        i = (i + 1) & g->mask;
    return i;
}

/* The cells of x's box (lo and hi indices); their count. */
static double cell_range(const capgrid *g, const dircap *x, int64_t lo[3], int64_t hi[3])
{
    double count = 1.0;
    for (int i = 0; i < 3; i++) {
        lo[i] = (int64_t)floor((x->c[i] - x->r + 2.5) / g->h);
        hi[i] = (int64_t)floor((x->c[i] + x->r + 2.5) / g->h);
        count *= (double)(hi[i] - lo[i] + 1);
    }
    return count;
}

static uint64_t cell_id(int64_t a, int64_t b, int64_t c)
{
    return ((uint64_t)a << 42) | ((uint64_t)b << 21) | (uint64_t)c;
}

/* Cap i's cells into the set: 0, or -1 when the set or the list is full. */
static int cap_insert(capgrid *g, const dircap *x, int i)
{
    int64_t lo[3], hi[3];
    if (cell_range(g, x, lo, hi) > CAP_INSERT_CELLS) {
        if (g->nbig == CAP_BIG)
            return -1;
        g->big[g->nbig++] = i;
        return 0;
    }
    for (int64_t a = lo[0]; a <= hi[0]; a++)
        for (int64_t b = lo[1]; b <= hi[1]; b++)
            for (int64_t c = lo[2]; c <= hi[2]; c++) {
                uint64_t k = cell_id(a, b, c);
                size_t s = slot_of(g, k);
                if (!g->key[s]) {
                    if (2 * (g->used + 1) > g->mask)
                        return -1;
                    g->key[s] = k + 1;
                    g->used++;
                }
            }
    return 0;
}

/* May cap q meet one of the set's? 1 also when its box spans too many
 * cells to look (the answer that keeps the triangle). */
static int cap_meets(const capgrid *g, const dircap *caps, const dircap *q)
{
    for (int i = 0; i < g->nbig; i++)
        if (caps_meet(q, &caps[g->big[i]]))
            return 1;
    int64_t lo[3], hi[3];
    if (cell_range(g, q, lo, hi) > CAP_CELLS)
        return 1;
    for (int64_t a = lo[0]; a <= hi[0]; a++)
        for (int64_t b = lo[1]; b <= hi[1]; b++)
            for (int64_t c = lo[2]; c <= hi[2]; c++)
                if (g->key[slot_of(g, cell_id(a, b, c))])
                    return 1;
    return 0;
}

/* The largest connected part of the triangles of mask (in[t] = 1),
 * connected through shared corners. 0, or -1 when out of memory. */
static int largest_part(const pd_mesh *m, const unsigned char *mask, unsigned char *in)
{
    int n = m->ntris, nv = m->nverts, best = -1;
    int *up = malloc(sizeof *up * (size_t)nv), *size = calloc((size_t)nv, sizeof *size);
    if (!up || !size) {
        free(up);
        free(size);
        return -1;
    }
    for (int i = 0; i < nv; i++)
        up[i] = i;
    for (int t = 0; t < n; t++)
        for (int k = 1; k < 3 && mask[t]; k++) {
            int a = root(up, m->tris[t][0]), b = root(up, m->tris[t][k]);
            if (a != b)
                up[a > b ? a : b] = a > b ? b : a;
        }
    for (int t = 0; t < n; t++)
        if (mask[t]) {
            int r = root(up, m->tris[t][0]);
            if (++size[r] > (best < 0 ? 0 : size[best]))
                best = r;
        }
    for (int t = 0; t < n; t++)
        in[t] = mask[t] && root(up, m->tris[t][0]) == best;
    free(up);
    free(size);
    return 0;
}

/* The triangles the search needs (keep[t] = 1) by the argument above,
 * for a closed and consistently oriented surface, o drawn from the planes
 * of the triangles of cand. 1 when the argument applies, 0 when not, -1
 * when out of memory. */
static int shadow_subset(search *s, const unsigned char *cand, unsigned char *keep)
{
    const pd_mesh *m = s->m;
    const pd_vec3 *v = m->verts;
    int n = m->ntris, ret = 0;
    pd_vec3 o;
    int exact = 0, kp = kernel_point(s, cand, &o, &exact);
    if (kp != 1)
        return kp;
    signed char *side = malloc((size_t)n);
    if (!side)
        return -1;
    int npos = 0, nneg = 0;
    for (int t = 0; t < n && !stop(s); t++) {
        const int *T = m->tris[t];
        side[t] = (signed char)pd_orient3d(&v[T[0]], &v[T[1]], &v[T[2]], &o);
        npos += side[t] > 0;
        nneg += side[t] < 0;
    }
    int front = npos >= nneg ? 1 : -1, nb = n - (front > 0 ? npos : nneg);
    long deg2 = LONG_MIN;
    for (int t = 0; t < n && t < 8 && deg2 == LONG_MIN && !s->cancelled && nb <= n / 3; t++) {
        const int *T = m->tris[t];
        pd_vec3 p = v3_scale(v3_add(v3_add(v[T[0]], v[T[1]]), v[T[2]]), 1.0 / 3.0);
        deg2 = line_degree(m, o, p, side, front);
    }
    dircap *caps = NULL;
    double *rs = NULL;
    capgrid g = {0};
    int ok = deg2 == 2 && nb > 0;
    if (ok) {
        caps = malloc(sizeof *caps * (size_t)nb);
        rs = malloc(sizeof *rs * (size_t)nb);
        ok = caps && rs;
        if (!ok)
            ret = -1;
    }
    int k = 0;
    for (int t = 0; t < n && ok; t++)
        if (side[t] != front) {
            ok = cap_of(m, t, o, &caps[k]);
            rs[k] = caps[k].r;
            k++;
        }
    if (ok) {
        /* Cells twice the median radius wide (a selection of it). */
        int mid = k / 2;
        for (int lo = 0, hi = k - 1; lo < hi;) {
            double piv = rs[lo + (hi - lo) / 2];
            int i = lo, j = hi;
            while (i <= j) {
                while (rs[i] < piv)
                    i++;
                while (rs[j] > piv)
                    j--;
                if (i <= j) {
                    double x = rs[i];
                    rs[i++] = rs[j];
                    rs[j--] = x;
                }
            }
            if (mid <= j)
                hi = j;
            else if (mid >= i)
                lo = i;
            else
                break;
        }
        g.h = dmax(2.0 * rs[mid], 1e-5);
        size_t slots = 1024;
        while (slots < 4 * (size_t)k && slots < ((size_t)1 << 22))
            slots *= 2;
        g.mask = slots - 1;
        g.key = calloc(slots, sizeof *g.key);
        ok = g.key != NULL;
        if (!ok)
            ret = -1;
        for (int i = 0; i < k && ok; i++)
            ok = cap_insert(&g, &caps[i], i) == 0;
    }
    for (int t = 0; t < n && ok && !stop(s); t++) {
        dircap q;
        keep[t] = side[t] != front || !cap_of(m, t, o, &q) || cap_meets(&g, caps, &q);
    }
    if (ok && !s->cancelled)
        ret = 1;
    free(side);
    free(caps);
    free(rs);
    free(g.key);
    return ret;
}

typedef struct edge {
    int b, t;
} edge;

static int edge_less(const edge *x, const edge *y)
{
    return x->b < y->b || (x->b == y->b && x->t < y->t);
}

static int edge_cmp(const void *pa, const void *pb)
{
    return edge_less(pa, pb) ? -1 : edge_less(pb, pa);
}

/* Sorts the few edges about one vertex: by insertion when they are few (the
 * usual star), by qsort otherwise (a fan of thousands about one corner). */
static void sort_edges(edge *e, int n)
{
    if (n > 24) {
        qsort(e, (size_t)n, sizeof *e, edge_cmp);
        return;
    }
    for (int i = 1; i < n; i++) {
        edge x = e[i];
        int j = i;
        for (; j > 0 && edge_less(&x, &e[j - 1]); j--)
            e[j] = e[j - 1];
        e[j] = x;
    }
}

/* Flat patches: triangles joined through shared edges to neighbours in
 * their plane, exactly (neither of the two degenerate, the fourth corner on
 * the plane of the other three); patch[t] names t's patch. Two triangles of
 * one patch lie in one plane (each step keeps the plane: two corners of the
 * edge and a third not on their line), and coplanar pairs are never found
 * crossing, so the search skips them: a flat face fanned into many
 * triangles about one corner would otherwise test every pair of them, each
 * sign an exact zero. The edges are taken vertex by vertex from the stars
 * (each edge at its lower vertex, the triangles along it in increasing
 * order, consecutive ones joined), not from one sort of all edges, which
 * cost a log more and a copy of them all. */
static int flat_patches(search *s)
{
    const pd_mesh *m = s->m;
    int *up = s->patch, maxdeg = 0;
    char *flat = malloc((size_t)m->ntris);
    if (!flat)
        return -1;
    for (int v = 0; v < m->nverts; v++)
        maxdeg = s->start[v + 1] - s->start[v] > maxdeg ? s->start[v + 1] - s->start[v] : maxdeg;
    edge *e = malloc(sizeof *e * (2 * (size_t)maxdeg + 1));
    if (!e) {
        free(flat);
        return -1;
    }
    for (int t = 0; t < m->ntris && !stop(s); t++) {
        up[t] = t;
        flat[t] = !degenerate(m, t);
    }
    for (int a = 0; a < m->nverts && !stop(s); a++) {
        int n = 0;
        for (int i = s->start[a]; i < s->start[a + 1]; i++) {
            int t = s->list[i];
            for (int k = 0; k < 3; k++)
                if (m->tris[t][k] == a) {
                    /* The edges of t from a: to the corners after and before it. */
                    int b1 = m->tris[t][(k + 1) % 3], b2 = m->tris[t][(k + 2) % 3];
                    if (b1 > a)
                        e[n++] = (edge){b1, t};
                    if (b2 > a && b2 != b1)
                        e[n++] = (edge){b2, t};
                    break;
                }
        }
        sort_edges(e, n);
        for (int i = 0; i + 1 < n; i++) {
            const edge *x = &e[i], *y = &e[i + 1];
            if (x->b != y->b || !flat[x->t] || !flat[y->t])
                continue;
            int c = -1, d = -1, b = x->b;
            for (int k = 0; k < 3; k++) {
                int vx = m->tris[x->t][k], vy = m->tris[y->t][k];
                if (vx != a && vx != b)
                    c = vx;
                if (vy != a && vy != b)
                    d = vy;
            }
            if (c < 0 || d < 0 || c == d)
                continue;
            if (orient(&m->verts[a], &m->verts[b], &m->verts[c], &m->verts[d]) == 0) {
                int rx = root(up, x->t), ry = root(up, y->t);
                up[rx > ry ? rx : ry] = rx > ry ? ry : rx;
            }
        }
    }
    free(e);
    free(flat);
    /* Each triangle's root, once: the tests below compare patches directly.
     * Cancelled, the patches may be half made, and no test follows. */
    for (int t = 0; t < m->ntris && !s->cancelled; t++)
        up[t] = root(up, t);
    return 0;
}

static int shared(const int a[3], const int b[3])
{
    int n = 0;
    for (int i = 0; i < 3; i++)
        n += (a[i] == b[0]) + (a[i] == b[1]) + (a[i] == b[2]);
    return n;
}

/* A filter in front of the exact test: triangle t's plane stored once as
 * pl = {nx, ny, nz, B}, floats, so that a triangle lying strictly on one side
 * of another's plane is set aside with three dot products.
 *
 * Why it is rigorous. Let T = (a, b, c) be t's corners, N = (b - a) x (c - a)
 * exact, nd the same computed in doubles and n = (float)nd; for a point p
 * the exact sign tested by side() is that of N . w, w = p - a. The filter
 * computes f = n . wd in doubles, wd = fl(p - a). With u = 2^-53 and R the
 * largest coordinate magnitude of the mesh (so |w_i|, |wd_i| <= 2R):
 *  - |nd_i - N_i| <= 5u P_i (two rounded differences in each product, the
 *    product and the subtraction: 4 roundings and second-order terms), P_i
 *    the permanent |u_y v_z| + |u_z v_y| (...) of the rounded edges;
 *  - |n_i - nd_i| <= 2^-24 |nd_i| <= 2^-24 (1 + 2^-23) |n_i| when nd_i is
 *    zero or within the range of normal floats;
 *  - |n . (wd - w)| <= u |n|_1 2R (one rounding per difference);
 *  - the computed dot product differs from n . wd by at most 3u |n|_1 2R
 *    (floats times doubles are exact in doubles only up to the rounding of
 *    each product and of the two sums).
 * So |f - N . w| <= 2R [2^-24 (1 + 2^-23) |n|_1 + 5u |P|_1 + 4u |n|_1]
 *                <= 2R 2^-23 (|n|_1 + |P|_1) = B,
 * each of the small u terms being far below the slack 2^-24 (|n|_1 + |P|_1)
 * that the factor 2^-23 leaves; B is evaluated in doubles (a relative error
 * of a few u, again inside that slack) and rounded up to a float. f > B then
 * means N . w > 0, exactly, and f < -B that N . w < 0. Products that could
 * underflow (a normal float component below FLT_MIN, or an nd too large for a
 * float) or edges below 2^-500 (whose products could fall below DBL_MIN and
 * lose their relative accuracy) make B infinite: that triangle is never set
 * aside. The remaining round-off, products of the dot below DBL_MIN, is
 * covered by PD_ORIENT3D_FILTER_ABS added at the comparison. */
static void plane_of(const pd_vec3 *v, const int T[3], double R, float pl[4])
{
    pd_vec3 a = v[T[0]], b = v[T[1]], c = v[T[2]];
    double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    double vx = c.x - a.x, vy = c.y - a.y, vz = c.z - a.z;
    double nd[3] = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
    double P = fabs(uy * vz) + fabs(uz * vy) + fabs(uz * vx) + fabs(ux * vz) + fabs(ux * vy) +
               fabs(uy * vx);
    double n1 = 0.0, e[6] = {ux, uy, uz, vx, vy, vz};
    int ok = isfinite(P);
    for (int i = 0; i < 6; i++)
        ok = ok && (e[i] == 0.0 || fabs(e[i]) >= 0x1p-500);
    for (int i = 0; i < 3; i++) {
        double x = fabs(nd[i]);
        ok = ok && (x == 0.0 || (x >= (double)FLT_MIN && x <= (double)FLT_MAX / 2));
        pl[i] = ok ? (float)nd[i] : 0.0f;
        n1 += fabs((double)pl[i]);
    }
    double B = 2.0 * R * 0x1p-23 * (n1 + P);
    float Bf = (float)B;
    if ((double)Bf < B)
        Bf = nextafterf(Bf, HUGE_VALF);
    pl[3] = ok && B < (double)FLT_MAX / 2 ? Bf : HUGE_VALF;
}

/* 1 when the filter proves that triangle p (corners P) does not straddle the
 * plane of triangle q (corners Q, plane pl) strictly: no corner certainly on
 * one side, each either a corner of q (sign 0, exactly, as side() has it) or
 * certainly on the other. side() then returns 0 and so does cross(). */
static int one_side(const pd_vec3 *v, const int P[3], const int Q[3], const float pl[4])
{
    double nx = pl[0], ny = pl[1], nz = pl[2], B = (double)pl[3] + PD_ORIENT3D_FILTER_ABS;
    const pd_vec3 *a = &v[Q[0]];
    int pos = 0, neg = 0;
    for (int i = 0; i < 3; i++) {
        if (P[i] == Q[0] || P[i] == Q[1] || P[i] == Q[2])
            continue;
        const pd_vec3 *p = &v[P[i]];
        double f = nx * (p->x - a->x) + ny * (p->y - a->y) + nz * (p->z - a->z);
        if (f > B)
            pos = 1;
        else if (f < -B)
            neg = 1;
        else
            return 0;
    }
    return !(pos && neg);
}

int pd_selfx_plane_filter(const pd_vec3 *v, const int a[3], const int b[3], double R)
{
    float pa[4], pb[4];
    plane_of(v, a, R, pa);
    plane_of(v, b, R, pb);
    return one_side(v, a, b, pb) || one_side(v, b, a, pa);
}

/* The exact test of triangles a and b (not of one flat patch); records them
 * when they cross. */
static int test_pair(search *s, int a, int b)
{
    if (s->patch[a] == s->patch[b])
        return 0;
    const int *A = s->m->tris[a], *B = s->m->tris[b];
    const pd_vec3 *v = s->m->verts;
    s->tested++;
    if (one_side(v, A, B, s->plane + 4 * (size_t)b) || one_side(v, B, A, s->plane + 4 * (size_t)a))
        return 0;
    const pd_vec3 *p[3] = {&v[A[0]], &v[A[1]], &v[A[2]]};
    const pd_vec3 *q[3] = {&v[B[0]], &v[B[1]], &v[B[2]]};
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

static int arc_less(const arc *a, const arc *b)
{
    return a->key < b->key || (a->key == b->key && a->t < b->t);
}

static int arc_cmp(const void *pa, const void *pb)
{
    return arc_less(pa, pb) ? -1 : arc_less(pb, pa);
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
        b->lo[i] = dmin(dmin(p[0][i], p[1][i]), p[2][i]) - PD_SELFX_ARC_PAD;
        b->hi[i] = dmax(dmax(p[0][i], p[1][i]), p[2][i]) + PD_SELFX_ARC_PAD;
    }
}

enum { SWEEP_MIN = 12 };

/* Sort and sweep of n boxes along the axis where they are shortest against
 * their spread; each pair whose boxes meet and that shares no edge goes to
 * the exact test. 1 when a crossing is found. */
static int sweep(search *s, arc *bx, int n)
{
    /* The usual star of five to eight: every pair, those that share an edge
     * set aside before their boxes; the sort pays only for large fans. */
    if (n <= SWEEP_MIN) {
        for (int a = 0; a < n; a++)
            for (int b = a + 1; b < n; b++) {
                if (shared(s->m->tris[bx[a].t], s->m->tris[bx[b].t]) >= 2 ||
                    bx[b].lo[0] > bx[a].hi[0] || bx[b].hi[0] < bx[a].lo[0] ||
                    bx[b].lo[1] > bx[a].hi[1] || bx[b].hi[1] < bx[a].lo[1] ||
                    bx[b].lo[2] > bx[a].hi[2] || bx[b].hi[2] < bx[a].lo[2])
                    continue;
                if (test_pair(s, bx[a].t, bx[b].t))
                    return 1;
            }
        return 0;
    }
    int ax = 0;
    double best = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        double lo = HUGE_VAL, hi = -HUGE_VAL, ext = 0.0;
        for (int i = 0; i < n; i++) {
            lo = dmin(lo, bx[i].lo[k]);
            hi = dmax(hi, bx[i].hi[k]);
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
    if (n > 16) {
        qsort(bx, (size_t)n, sizeof *bx, arc_cmp);
    } else {
        for (int i = 1; i < n; i++) {
            arc x = bx[i];
            int j = i;
            for (; j > 0 && arc_less(&x, &bx[j - 1]); j--)
                bx[j] = bx[j - 1];
            bx[j] = x;
        }
    }
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
 * 1 when a crossing is found (or the search is cancelled), -1 when out of
 * memory. */
static int star_pairs(search *s)
{
    const pd_mesh *m = s->m;
    int nv = m->nverts, found = 0, maxdeg = 0;
    for (int v = 0; v < nv; v++)
        maxdeg = s->start[v + 1] - s->start[v] > maxdeg ? s->start[v + 1] - s->start[v] : maxdeg;
    arc *bx = malloc(sizeof *bx * ((size_t)maxdeg + 1));
    if (!bx)
        return -1;
    for (int v = 0; v < nv && !found; v++) {
        int n = s->start[v + 1] - s->start[v];
        for (int i = 0; i < n; i++)
            arc_box(m, s->list[s->start[v] + i], v, &bx[i]);
        found = sweep(s, bx, n) || stop(s);
    }
    free(bx);
    return found;
}

/* Pairs that share no vertex: a tree of boxes whose leaves are groups of
 * up to LEAF_TRIS neighbouring triangles of the surface (grow_groups) and
 * whose upper levels split the groups by the surface-area heuristic, each
 * box oriented along the longest edge of its triangles and the normal of
 * that edge's triangle (a spike of a noisy scan, a sliver of a rod turned
 * off the axes: its box is as thin as it is, where a box along the
 * coordinate axes would span the part). Two boxes are apart when their
 * projections on one of their six axes are apart, a triangle projecting its
 * corners and a box its centre and half-widths; every projection is widened
 * by pad, far above the round-off of the frames and dot products, so a pair
 * that may cross is never dropped: the exact test decides. A node's corners
 * common to all its triangles, and its flat patch, skip a pair of nodes
 * whose triangles all share a vertex (taken by the stars) or a plane. The
 * traversal visits the pairs of nodes whose boxes meet. */
enum { LEAF_TRIS = 8, REFIT_TRIS = 64 };

typedef struct bnode {
    pd_vec3 ax[3];       /* orthonormal to round-off */
    double lo[3], hi[3]; /* the projections on ax of its corners, widened */
    int cv[3];           /* corners common to all its triangles, -1 for none */
    int patch;           /* the flat patch of all its triangles, or -1 */
    int first, count;    /* its triangles: order[first .. first + count) */
    int left;            /* children left and left + 1; -1 for a leaf */
    float alo[3], ahi[3]; /* its box along the coordinate axes, widened by pad and
                             rounded outwards: six comparisons that settle
                             many pairs (most, on smooth surfaces) before the
                             27 products of the oriented test */
} bnode;

/* A triangle's box along the coordinate axes, in floats: it only guides
 * the split (a split that rounding makes worse is still a split), never
 * decides a pair. */
typedef struct item {
    float lo[3], hi[3];
    int t;
} item;

typedef struct bvh {
    bnode *nodes;
    int nn, cap, *order;
    item *items;                /* one per patch */
    int *members, *patch_start; /* patch i: members[patch_start[i] .. patch_start[i + 1]) */
    int filled;                 /* triangles laid out in order so far */
} bvh;

/* An orthonormal frame (to round-off) with ax[0] along d, ax[1] in the
 * plane of d and e (or across d from the coordinate axis least along it,
 * when e is along d: a degenerate triangle); the coordinate axes when d has
 * no direction. Every box below is sound in any orthonormal frame, and in
 * no other: a frame whose axes came out parallel (the unit vector of a
 * remainder that was round-off) once set apart two triangles that cross. */
static void frame(pd_vec3 ax[3], pd_vec3 d, pd_vec3 e)
{
    pd_vec3 a = v3_unit(d);
    if (!(v3_dot(a, a) > 0.5) || !v3_isfinite(a)) {
        ax[0] = v3(1, 0, 0);
        ax[1] = v3(0, 1, 0);
        ax[2] = v3(0, 0, 1);
        return;
    }
    pd_vec3 b = v3_sub(e, v3_scale(a, v3_dot(a, e)));
    if (!(v3_dot(b, b) > 1e-12 * v3_dot(e, e)) || !v3_isfinite(b)) {
        double c[3] = {fabs(a.x), fabs(a.y), fabs(a.z)};
        int k = c[0] <= c[1] && c[0] <= c[2] ? 0 : c[1] <= c[2] ? 1 : 2;
        pd_vec3 u = v3(k == 0, k == 1, k == 2);
        b = v3_sub(u, v3_scale(a, v3_dot(a, u)));
    }
    b = v3_unit(b);
    b = v3_unit(v3_sub(b, v3_scale(a, v3_dot(a, b))));
    pd_vec3 c = v3_cross(a, b);
    if (!(fabs(v3_dot(a, b)) < 1e-12) || !(fabs(v3_dot(c, c) - 1.0) < 1e-12)) {
        ax[0] = v3(1, 0, 0);
        ax[1] = v3(0, 1, 0);
        ax[2] = v3(0, 0, 1);
        return;
    }
    ax[0] = a;
    ax[1] = b;
    ax[2] = c;
}

/* The surface area of a box, half of it: the chance, for a box of
 * random lines or boxes passing through the parent, to be met (the
 * surface-area heuristic). */
static double half_area(const float lo[3], const float hi[3])
{
    double e0 = (double)hi[0] - (double)lo[0], e1 = (double)hi[1] - (double)lo[1],
           e2 = (double)hi[2] - (double)lo[2];
    return e0 * e1 + e1 * e2 + e2 * e0;
}

static void box_grow(float lo[3], float hi[3], const item *x)
{
    for (int k = 0; k < 3; k++) {
        lo[k] = x->lo[k] < lo[k] ? x->lo[k] : lo[k];
        hi[k] = x->hi[k] > hi[k] ? x->hi[k] : hi[k];
    }
}

/* Splits it[0 .. n) in two, by the surface-area heuristic over SPLIT_BINS
 * bins of the boxes' centres along each axis: the plane that leaves the
 * least summed area times count on its two sides. Returns the count of the
 * first part, 0 < it < n (the middle when every centre is in one bin). A
 * split by centres alone, along the longest spread, cuts a noisy scan's
 * radial spikes across their length: both halves then span the whole
 * shell, and every box meets its neighbours along the radius. */
enum { SPLIT_BINS = 12, SAMPLE = 2048 };

static int sah_split(item *it, int n)
{
    /* A large node's plane is chosen from a sample of its boxes (one in
     * stride, about SAMPLE of them): the binning of every box at every level
     * was most of the build. The partition then takes them all. */
    int stride = n > 2 * SAMPLE ? n / SAMPLE : 1;
    float cl[3] = {HUGE_VALF, HUGE_VALF, HUGE_VALF}, ch[3] = {-HUGE_VALF, -HUGE_VALF, -HUGE_VALF};
    for (int i = 0; i < n; i += stride)
        for (int k = 0; k < 3; k++) {
            float c = it[i].lo[k] + it[i].hi[k];
            cl[k] = c < cl[k] ? c : cl[k];
            ch[k] = c > ch[k] ? c : ch[k];
        }
    int best_ax = -1, best_bin = 0;
    double best = HUGE_VAL;
    for (int k = 0; k < 3; k++) {
        if (!(ch[k] > cl[k]))
            continue;
        float blo[SPLIT_BINS][3], bhi[SPLIT_BINS][3];
        int cnt[SPLIT_BINS] = {0};
        for (int b = 0; b < SPLIT_BINS; b++)
            for (int j = 0; j < 3; j++) {
                blo[b][j] = HUGE_VALF;
                bhi[b][j] = -HUGE_VALF;
            }
        double scale = SPLIT_BINS / ((double)ch[k] - (double)cl[k]) * (1.0 - 1e-6);
        for (int i = 0; i < n; i += stride) {
            int b = (int)(((double)(it[i].lo[k] + it[i].hi[k]) - (double)cl[k]) * scale);
            b = b < 0 ? 0 : b >= SPLIT_BINS ? SPLIT_BINS - 1 : b;
            cnt[b]++;
            box_grow(blo[b], bhi[b], &it[i]);
        }
        /* Areas of the bins left of each plane, then sweep from the right. */
        double left[SPLIT_BINS];
        float lo[3] = {HUGE_VALF, HUGE_VALF, HUGE_VALF}, hi[3] = {-HUGE_VALF, -HUGE_VALF, -HUGE_VALF};
        int nl = 0, nleft[SPLIT_BINS];
        for (int b = 0; b < SPLIT_BINS - 1; b++) {
            if (cnt[b]) {
                item x = {{blo[b][0], blo[b][1], blo[b][2]}, {bhi[b][0], bhi[b][1], bhi[b][2]}, 0};
                box_grow(lo, hi, &x);
            }
            nl += cnt[b];
            nleft[b] = nl;
            left[b] = nl ? half_area(lo, hi) * nl : 0.0;
        }
        for (int j = 0; j < 3; j++) {
            lo[j] = HUGE_VALF;
            hi[j] = -HUGE_VALF;
        }
        int nr = 0;
        for (int b = SPLIT_BINS - 1; b > 0; b--) {
            if (cnt[b]) {
                item x = {{blo[b][0], blo[b][1], blo[b][2]}, {bhi[b][0], bhi[b][1], bhi[b][2]}, 0};
                box_grow(lo, hi, &x);
            }
            nr += cnt[b];
            if (nr == 0 || nleft[b - 1] == 0)
                continue;
            double cost = left[b - 1] + half_area(lo, hi) * nr;
            if (cost < best) {
                best = cost;
                best_ax = k;
                best_bin = b;
            }
        }
    }
    if (best_ax < 0)
        return n / 2;
    int k = best_ax;
    double scale = SPLIT_BINS / ((double)ch[k] - (double)cl[k]) * (1.0 - 1e-6);
    int i = 0, j = n - 1;
    while (i <= j) {
        int b = (int)(((double)(it[i].lo[k] + it[i].hi[k]) - (double)cl[k]) * scale);
        if (b < best_bin) {
            i++;
        } else {
            item x = it[i];
            it[i] = it[j];
            it[j--] = x;
        }
    }
    return i > 0 && i < n ? i : n / 2;
}

/* The projection of node b's box on the unit axis w, widened by pad. */
static void box_on(const bnode *b, pd_vec3 w, double pad, double *lo, double *hi)
{
    double c = 0.0, r = 0.0;
    for (int k = 0; k < 3; k++) {
        double wk = v3_dot(w, b->ax[k]);
        c += 0.5 * (b->lo[k] + b->hi[k]) * wk;
        r += 0.5 * (b->hi[k] - b->lo[k]) * fabs(wk);
    }
    *lo = c - r - pad;
    *hi = c + r + pad;
}

/* Node nd's box in its frame, fitted to its triangles' corners. */
static void fit_corners(const search *s, const bvh *tr, bnode *nd)
{
    const pd_mesh *m = s->m;
    const int *ts = tr->order + nd->first;
    for (int k = 0; k < 3; k++) {
        nd->lo[k] = HUGE_VAL;
        nd->hi[k] = -HUGE_VAL;
    }
    for (int i = 0; i < nd->count; i++)
        for (int j = 0; j < 3; j++) {
            pd_vec3 p = m->verts[m->tris[ts[i]][j]];
            for (int k = 0; k < 3; k++) {
                double x = v3_dot(nd->ax[k], p);
                nd->lo[k] = dmin(nd->lo[k], x);
                nd->hi[k] = dmax(nd->hi[k], x);
            }
        }
    for (int k = 0; k < 3; k++) {
        nd->lo[k] -= s->pad;
        nd->hi[k] += s->pad;
    }
}

/* A leaf's box along the coordinate axes, in floats rounded outwards (a
 * float beyond the double's bound stepped back by one), so that it holds
 * the corners whatever the rounding. */
static void fit_axis_box(const search *s, const bvh *tr, bnode *nd)
{
    const pd_mesh *m = s->m;
    const int *ts = tr->order + nd->first;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (int i = 0; i < nd->count; i++)
        for (int j = 0; j < 3; j++) {
            pd_vec3 p = m->verts[m->tris[ts[i]][j]];
            double c[3] = {p.x, p.y, p.z};
            for (int k = 0; k < 3; k++) {
                lo[k] = dmin(lo[k], c[k]);
                hi[k] = dmax(hi[k], c[k]);
            }
        }
    for (int k = 0; k < 3; k++) {
        float l = (float)(lo[k] - s->pad), h = (float)(hi[k] + s->pad);
        nd->alo[k] = (double)l > lo[k] - s->pad ? nextafterf(l, -HUGE_VALF) : l;
        nd->ahi[k] = (double)h < hi[k] + s->pad ? nextafterf(h, HUGE_VALF) : h;
    }
}

/* A leaf: its frame along its longest edge and the normal of that edge's
 * triangle. */
static void fit_leaf(search *s, const bvh *tr, bnode *nd)
{
    const pd_mesh *m = s->m;
    const int *ts = tr->order + nd->first;
    int n = nd->count, lt = ts[0], lk = 0;
    double best = -1.0;
    for (int i = 0; i < n; i++) {
        const int *T = m->tris[ts[i]];
        for (int k = 0; k < 3; k++) {
            pd_vec3 e = v3_sub(m->verts[T[(k + 1) % 3]], m->verts[T[k]]);
            if (v3_dot(e, e) > best) {
                best = v3_dot(e, e);
                lt = ts[i];
                lk = k;
            }
        }
    }
    const int *T = m->tris[lt];
    frame(nd->ax, v3_sub(m->verts[T[(lk + 1) % 3]], m->verts[T[lk]]),
          v3_sub(m->verts[T[(lk + 2) % 3]], m->verts[T[(lk + 1) % 3]]));
    fit_corners(s, tr, nd);
    fit_axis_box(s, tr, nd);
    int nc = 0;
    for (int k = 0; k < 3; k++) {
        int v = m->tris[ts[0]][k], all = 1;
        for (int i = 1; i < n && all; i++)
            all = m->tris[ts[i]][0] == v || m->tris[ts[i]][1] == v || m->tris[ts[i]][2] == v;
        if (all)
            nd->cv[nc++] = v;
    }
    while (nc < 3)
        nd->cv[nc++] = -1;
    nd->patch = s->patch[ts[0]];
    for (int i = 1; i < n; i++)
        if (s->patch[ts[i]] != nd->patch)
            nd->patch = -1;
}

/* Builds node id over the patches items[first .. first + count): a leaf
 * of one patch, its triangles appended to order, or two children that
 * split the patches by the surface-area heuristic. */
static int build(search *s, bvh *tr, int id, int first, int count)
{
    /* A cancelled build stops as one out of memory does; the caller tells
     * them apart by s->cancelled. */
    if (stop(s))
        return -1;
    bnode *nd = &tr->nodes[id];
    nd->first = tr->filled;
    if (count == 1) {
        const int *pt = tr->members + tr->patch_start[tr->items[first].t];
        nd->count = tr->patch_start[tr->items[first].t + 1] - tr->patch_start[tr->items[first].t];
        nd->left = -1;
        for (int i = 0; i < nd->count; i++)
            tr->order[tr->filled++] = pt[i];
        fit_leaf(s, tr, nd);
        return 0;
    }
    if (tr->nn + 2 > tr->cap) {
        size_t cap = 2 * (size_t)tr->cap;
        bnode *more = realloc(tr->nodes, sizeof *more * cap);
        if (!more)
            return -1;
        tr->nodes = more;
        tr->cap = (int)cap;
    }
    int nl = sah_split(tr->items + first, count), l = tr->nn;
    tr->nn += 2;
    tr->nodes[id].left = l;
    if (build(s, tr, l, first, nl) != 0 || build(s, tr, l + 1, first + nl, count - nl) != 0)
        return -1;
    nd = &tr->nodes[id];
    nd->count = tr->filled - nd->first;
    const bnode *c[2] = {&tr->nodes[l], &tr->nodes[l + 1]};
    /* The frame of either child, or the coordinate axes, whichever holds
     * both children's boxes in the least surface: a frame kept from the
     * children alone would, level after level, hold boxes turned against it
     * and grow them (on a noisy sphere the root's box came out 30 times the
     * sphere). */
    pd_vec3 cand[3][3] = {{c[0]->ax[0], c[0]->ax[1], c[0]->ax[2]},
                          {c[1]->ax[0], c[1]->ax[1], c[1]->ax[2]},
                          {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)}};
    double best = HUGE_VAL;
    for (int f = 0; f < 3; f++) {
        double lo[3], hi[3], e[3];
        for (int k = 0; k < 3; k++) {
            double lo0, hi0, lo1, hi1;
            box_on(c[0], cand[f][k], s->pad, &lo0, &hi0);
            box_on(c[1], cand[f][k], s->pad, &lo1, &hi1);
            lo[k] = dmin(lo0, lo1);
            hi[k] = dmax(hi0, hi1);
            e[k] = hi[k] - lo[k];
        }
        double area = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
        if (area < best) {
            best = area;
            for (int k = 0; k < 3; k++) {
                nd->ax[k] = cand[f][k];
                nd->lo[k] = lo[k];
                nd->hi[k] = hi[k];
            }
        }
    }
    /* Near the leaves, the box fitted to the corners themselves: a few
     * levels of them cost a few passes over the corners. */
    if (count <= REFIT_TRIS)
        fit_corners(s, tr, nd);
    int nc = 0;
    for (int i = 0; i < 3; i++) {
        int v = c[0]->cv[i];
        if (v >= 0 && (v == c[1]->cv[0] || v == c[1]->cv[1] || v == c[1]->cv[2]))
            nd->cv[nc++] = v;
    }
    while (nc < 3)
        nd->cv[nc++] = -1;
    nd->patch = c[0]->patch == c[1]->patch ? c[0]->patch : -1;
    for (int k = 0; k < 3; k++) {
        nd->alo[k] = c[0]->alo[k] < c[1]->alo[k] ? c[0]->alo[k] : c[1]->alo[k];
        nd->ahi[k] = c[0]->ahi[k] > c[1]->ahi[k] ? c[0]->ahi[k] : c[1]->ahi[k];
    }
    return 0;
}

/* Are the boxes of nodes a and b apart along one of their six axes? R[i][j]
 * = a.ax[i] . b.ax[j] takes each box's centre and half-widths onto the
 * other's axes. */
static int boxes_apart(const bnode *a, const bnode *b, double pad)
{
    double R[3][3], ca[3], ra[3], cb[3], rb[3];
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            R[i][j] = v3_dot(a->ax[i], b->ax[j]);
        ca[i] = 0.5 * (a->lo[i] + a->hi[i]);
        ra[i] = 0.5 * (a->hi[i] - a->lo[i]);
        cb[i] = 0.5 * (b->lo[i] + b->hi[i]);
        rb[i] = 0.5 * (b->hi[i] - b->lo[i]);
    }
    for (int i = 0; i < 3; i++) {
        double c = cb[0] * R[i][0] + cb[1] * R[i][1] + cb[2] * R[i][2];
        double r = rb[0] * fabs(R[i][0]) + rb[1] * fabs(R[i][1]) + rb[2] * fabs(R[i][2]) + pad;
        if (c + r < a->lo[i] || c - r > a->hi[i])
            return 1;
    }
    for (int j = 0; j < 3; j++) {
        double c = ca[0] * R[0][j] + ca[1] * R[1][j] + ca[2] * R[2][j];
        double r = ra[0] * fabs(R[0][j]) + ra[1] * fabs(R[1][j]) + ra[2] * fabs(R[2][j]) + pad;
        if (c + r < b->lo[j] || c - r > b->hi[j])
            return 1;
    }
    return 0;
}

/* Is triangle t apart from node b's box along one of its axes? */
static int tri_apart(const search *s, int t, const bnode *b)
{
    const int *T = s->m->tris[t];
    const pd_vec3 *v = s->m->verts;
    for (int k = 0; k < 3; k++) {
        double x0 = v3_dot(b->ax[k], v[T[0]]), x1 = v3_dot(b->ax[k], v[T[1]]),
               x2 = v3_dot(b->ax[k], v[T[2]]);
        if (dmax(dmax(x0, x1), x2) + s->pad < b->lo[k] ||
            dmin(dmin(x0, x1), x2) - s->pad > b->hi[k])
            return 1;
    }
    return 0;
}

/* A triangle's box along the coordinate axes (exact: its corners' own
 * coordinates). */
typedef struct tbox {
    double lo[3], hi[3];
    int t;
} tbox;

static void tri_box(const search *s, int t, tbox *b)
{
    const int *T = s->m->tris[t];
    const pd_vec3 *v = s->m->verts;
    b->t = t;
    b->lo[0] = dmin(dmin(v[T[0]].x, v[T[1]].x), v[T[2]].x);
    b->hi[0] = dmax(dmax(v[T[0]].x, v[T[1]].x), v[T[2]].x);
    b->lo[1] = dmin(dmin(v[T[0]].y, v[T[1]].y), v[T[2]].y);
    b->hi[1] = dmax(dmax(v[T[0]].y, v[T[1]].y), v[T[2]].y);
    b->lo[2] = dmin(dmin(v[T[0]].z, v[T[1]].z), v[T[2]].z);
    b->hi[2] = dmax(dmax(v[T[0]].z, v[T[1]].z), v[T[2]].z);
}

/* Triangles a and b (boxes x and y), sharing no vertex, unless their
 * boxes are apart. */
static int tri_pair(search *s, const tbox *x, const tbox *y)
{
    for (int k = 0; k < 3; k++)
        if (x->hi[k] < y->lo[k] || y->hi[k] < x->lo[k])
            return 0;
    if (shared(s->m->tris[x->t], s->m->tris[y->t]) > 0)
        return 0;
    return test_pair(s, x->t, y->t);
}

static int common_corner(const bnode *a, const bnode *b)
{
    for (int i = 0; i < 3 && a->cv[i] >= 0; i++)
        if (a->cv[i] == b->cv[0] || a->cv[i] == b->cv[1] || a->cv[i] == b->cv[2])
            return 1;
    return 0;
}

/* Two leaves: each one's triangles not apart from the other's box, then
 * their pairs. */
static int leaf_pair(search *s, const bvh *tr, const bnode *a, const bnode *b)
{
    tbox xa[LEAF_TRIS], xb[LEAF_TRIS];
    int na = 0, nb = 0;
    for (int i = 0; i < a->count; i++) {
        int t = tr->order[a->first + i];
        if (!tri_apart(s, t, b))
            tri_box(s, t, &xa[na++]);
    }
    if (na == 0)
        return 0;
    for (int j = 0; j < b->count; j++) {
        int t = tr->order[b->first + j];
        if (!tri_apart(s, t, a))
            tri_box(s, t, &xb[nb++]);
    }
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++)
            if (tri_pair(s, &xa[i], &xb[j]))
                return 1;
    return 0;
}

static int node_pair(search *s, const bvh *tr, int ia, int ib)
{
    const bnode *a = &tr->nodes[ia], *b = &tr->nodes[ib];
    if (a->ahi[0] < b->alo[0] || b->ahi[0] < a->alo[0] || a->ahi[1] < b->alo[1] ||
        b->ahi[1] < a->alo[1] || a->ahi[2] < b->alo[2] || b->ahi[2] < a->alo[2] ||
        common_corner(a, b) || (a->patch >= 0 && a->patch == b->patch) ||
        boxes_apart(a, b, s->pad))
        return 0;
    if (stop(s))
        return 1;
    if (a->left < 0 && b->left < 0)
        return leaf_pair(s, tr, a, b);
    if (b->left < 0 || (a->left >= 0 && a->count >= b->count))
        return node_pair(s, tr, a->left, ib) || node_pair(s, tr, a->left + 1, ib);
    return node_pair(s, tr, ia, b->left) || node_pair(s, tr, ia, b->left + 1);
}

static int node_self(search *s, const bvh *tr, int id)
{
    const bnode *nd = &tr->nodes[id];
    if (nd->cv[0] >= 0 || nd->patch >= 0)
        return 0;
    if (stop(s))
        return 1;
    if (nd->left < 0) {
        tbox x[LEAF_TRIS];
        for (int i = 0; i < nd->count; i++)
            tri_box(s, tr->order[nd->first + i], &x[i]);
        for (int i = 0; i < nd->count; i++)
            for (int j = i + 1; j < nd->count; j++)
                if (tri_pair(s, &x[i], &x[j]))
                    return 1;
        return 0;
    }
    return node_self(s, tr, nd->left) || node_self(s, tr, nd->left + 1) ||
           node_pair(s, tr, nd->left, nd->left + 1);
}

/* The leaves' groups. First the fans: the triangles about a vertex of
 * more than FAN_TRIS, LEAF_TRIS at a time in the star's order (a polygon
 * fanned from one corner: runs of neighbouring wedges, all about that
 * corner, whose pairs the corner tests skip; long wedges spread over the
 * leaves of their other corners would meet one another's boxes at the
 * fan's corner, every leaf with every other). Then groups of up to
 * LEAF_TRIS grown from a seed over shared corners, breadth first (the
 * triangles about each corner of the seed, then about theirs), seeds in
 * the order of the triangles. A leaf of triangles whose centres or boxes
 * lie close together gathers, on a noisy scan whose spikes span the shell,
 * spikes from a patch of the surface many spikes wide at different depths,
 * and its box meets those of every leaf stacked over that patch; a group
 * grown over the surface is a patch a few triangles wide. Any grouping is
 * sound: every pair of triangles is still under one node, in one leaf or
 * across two children. 0, or -1 when out of memory or cancelled. */
enum { FAN_TRIS = 32 };

static int grow_groups(search *s, bvh *tr, int *ngroups)
{
    const pd_mesh *m = s->m;
    int n = m->ntris, ng = 0, filled = 0;
    char *taken = calloc((size_t)n, 1);
    tr->members = malloc(sizeof *tr->members * (size_t)n);
    tr->patch_start = malloc(sizeof *tr->patch_start * ((size_t)n + 1));
    if (!taken || !tr->members || !tr->patch_start) {
        free(taken);
        return -1;
    }
    int *mb = tr->members;
    for (int v = 0; v < m->nverts; v++) {
        if (s->start[v + 1] - s->start[v] <= FAN_TRIS)
            continue;
        int in = LEAF_TRIS;
        for (int i = s->start[v]; i < s->start[v + 1]; i++) {
            int t = s->list[i];
            if (taken[t])
                continue;
            if (in == LEAF_TRIS) {
                tr->patch_start[ng++] = filled;
                in = 0;
            }
            taken[t] = 1;
            mb[filled++] = t;
            in++;
        }
    }
    for (int seed = 0; seed < n; seed++) {
        if (taken[seed])
            continue;
        if (stop(s)) {
            free(taken);
            return -1;
        }
        int first = filled;
        tr->patch_start[ng++] = first;
        taken[seed] = 1;
        mb[filled++] = seed;
        for (int q = first; q < filled && filled - first < LEAF_TRIS; q++) {
            const int *T = m->tris[mb[q]];
            for (int k = 0; k < 3 && filled - first < LEAF_TRIS; k++)
                for (int i = s->start[T[k]]; i < s->start[T[k] + 1] && filled - first < LEAF_TRIS;
                     i++) {
                    int u = s->list[i];
                    if (!taken[u]) {
                        taken[u] = 1;
                        mb[filled++] = u;
                    }
                }
        }
    }
    tr->patch_start[ng] = filled;
    free(taken);
    *ngroups = ng;
    return 0;
}

/* 1 when a crossing is found (or the search is cancelled), -1 when out of
 * memory. Frees the stars once the leaves' groups are grown. */
static int apart_pairs(search *s)
{
    const pd_mesh *m = s->m;
    size_t n = (size_t)m->ntris;
    bvh tr = {0};
    int ng = 0, found = -1;
    int grown = grow_groups(s, &tr, &ng);
    free(s->start);
    free(s->list);
    s->start = s->list = NULL;
    if (grown == 0) {
        tr.nn = 1;
        tr.cap = 2 * ng;
        tr.order = malloc(sizeof *tr.order * n);
        tr.items = malloc(sizeof *tr.items * (size_t)ng);
        tr.nodes = malloc(sizeof *tr.nodes * (size_t)tr.cap);
    }
    if (grown != 0 && s->cancelled)
        found = 1;
    else if (tr.order && tr.items && tr.nodes) {
        const pd_vec3 *v = m->verts;
        for (int g = 0; g < ng; g++) {
            double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
            for (int i = tr.patch_start[g]; i < tr.patch_start[g + 1]; i++) {
                const int *T = m->tris[tr.members[i]];
                for (int k = 0; k < 3; k++) {
                    double c[3] = {v[T[k]].x, v[T[k]].y, v[T[k]].z};
                    for (int j = 0; j < 3; j++) {
                        lo[j] = dmin(lo[j], c[j]);
                        hi[j] = dmax(hi[j], c[j]);
                    }
                }
            }
            item *x = &tr.items[g];
            for (int k = 0; k < 3; k++) {
                x->lo[k] = (float)lo[k];
                x->hi[k] = (float)hi[k];
            }
            x->t = g;
        }
        if (stop(s))
            found = 1;
        else if (build(s, &tr, 0, 0, ng) == 0) {
            free(tr.items);
            free(tr.members);
            free(tr.patch_start);
            tr.items = NULL;
            tr.members = tr.patch_start = NULL;
            found = node_self(s, &tr, 0);
        }
    }
    free(tr.nodes);
    free(tr.order);
    free(tr.items);
    free(tr.members);
    free(tr.patch_start);
    return found;
}

/* The triangles a crossing can involve: those every point o tried keeps
 * (each point's set holds every crossing pair, so their intersection
 * does), o drawn first from the largest connected part, then from the
 * largest connected part of what is still kept (on a part of several
 * shells, the next shell), while a round takes away a tenth of what is
 * left. *nk < ntris when narrowed. 0, or -1 when out of memory. */
enum { NARROW_ROUNDS = 3 };

static int narrow(search *s, unsigned char *keep, int *nk)
{
    const pd_mesh *m = s->m;
    int n = m->ntris;
    unsigned char *cand = malloc((size_t)n), *cur = malloc((size_t)n);
    int st = cand && cur ? 0 : -1;
    memset(keep, 1, (size_t)n);
    *nk = n;
    for (int round = 0; round < NARROW_ROUNDS && st == 0 && *nk >= 2; round++) {
        if (largest_part(m, keep, cand) != 0) {
            st = -1;
            break;
        }
        int r = shadow_subset(s, cand, cur);
        if (r <= 0) {
            st = r;
            break;
        }
        int left = 0;
        for (int t = 0; t < n; t++) {
            keep[t] &= cur[t];
            left += keep[t];
        }
        int enough = left > *nk - *nk / 10;
        *nk = left;
        if (enough)
            break;
    }
    free(cand);
    free(cur);
    return st;
}

/* The search over all of s's mesh (its stars built): 1 when a crossing
 * is found (or the search is cancelled), 0 when none, -1 when out of
 * memory. */
static int search_pairs(search *s, double R)
{
    const pd_mesh *m = s->m;
    for (int t = 0; t < m->ntris; t++)
        plane_of(m->verts, m->tris[t], R, s->plane + 4 * (size_t)t);
    if (flat_patches(s) != 0)
        return -1;
    int found = s->cancelled ? 1 : star_pairs(s);
    return found == 0 ? apart_pairs(s) : found;
}

/* The search over the nk triangles of keep (shadow_subset), as a mesh of
 * its own on the same vertices; the pair found named by the triangles of
 * s's mesh. */
static int search_part(search *s, const unsigned char *keep, int nk, double R)
{
    const pd_mesh *m = s->m;
    int *idx = malloc(sizeof *idx * (size_t)nk), found = -1;
    int(*tris)[3] = malloc(sizeof *tris * (size_t)nk);
    free(s->start);
    free(s->list);
    s->start = s->list = NULL;
    pd_mesh part = {m->nverts, m->verts, nk, tris};
    search p = *s;
    p.m = &part;
    p.patch = p.start = p.list = NULL;
    p.plane = NULL;
    if (idx && tris) {
        for (int t = 0, k = 0; t < m->ntris; t++)
            if (keep[t]) {
                idx[k] = t;
                memcpy(tris[k++], m->tris[t], sizeof *tris);
            }
        p.patch = malloc(sizeof *p.patch * (size_t)nk);
        p.plane = malloc(sizeof *p.plane * 4 * (size_t)nk);
        if (p.patch && p.plane && build_stars(&p) == 0)
            found = search_pairs(&p, R);
    }
    s->tested = p.tested;
    s->cancelled = p.cancelled;
    s->polls = p.polls;
    if (found == 1 && !p.cancelled) {
        s->ta = idx[p.ta] < idx[p.tb] ? idx[p.ta] : idx[p.tb];
        s->tb = idx[p.ta] < idx[p.tb] ? idx[p.tb] : idx[p.ta];
        s->at = p.at;
    }
    free(p.patch);
    free(p.plane);
    free(p.start);
    free(p.list);
    free(idx);
    free(tris);
    return found;
}

pd_status pd_mesh_self_crossing(const pd_mesh *m, pd_cancel_flag *cancel, int *ta, int *tb,
                                pd_vec3 *at, size_t *tested)
{
    *ta = *tb = -1;
    if (tested)
        *tested = 0;
    if (cancel && atomic_load_explicit(cancel, memory_order_relaxed))
        return PD_ERR_CANCELLED;
    if (m->ntris < 2)
        return PD_OK;
    double R = 0.0;
    for (int i = 0; i < m->nverts; i++)
        R = dmax(R, dmax(fabs(m->verts[i].x), dmax(fabs(m->verts[i].y), fabs(m->verts[i].z))));
    search s = {m, malloc(sizeof *s.patch * (size_t)m->ntris), NULL, NULL, PD_SELFX_PAD_REL * R,
                malloc(sizeof *s.plane * 4 * (size_t)m->ntris), 0, -1, -1, {0, 0, 0}, cancel, 0, 0};
    int found = -1, star = -1, closed = 0;
    if (s.patch && s.plane && build_stars(&s) == 0)
        star = star_shaped(&s, &closed);
    if (star == 1)
        found = 0;
    else if (star == 0) {
        int nk = m->ntris, sh = 0;
        unsigned char *keep = closed == 1 ? malloc((size_t)m->ntris) : NULL;
        if (closed == 1)
            sh = keep ? narrow(&s, keep, &nk) : -1;
        if (s.cancelled)
            found = 1; /* the search's answer when cancelled */
        else if (sh == 0 && nk < 2)
            found = 0; /* a crossing takes two triangles */
        else if (sh == 0 && nk < m->ntris - m->ntris / 10) {
            found = search_part(&s, keep, nk, R);
            /* A crossing found in the part is confirmed, and named, by the
             * search over the whole: the part's flat patches may be split
             * where their linking triangles were left out, so that a fold
             * within one patch, which the whole search passes, would count
             * as a crossing. A mesh that crosses is refused anyway; this
             * costs only such meshes. */
            if (found == 1 && !s.cancelled)
                found = build_stars(&s) == 0 ? search_pairs(&s, R) : -1;
        }
        else if (sh == 0)
            found = search_pairs(&s, R);
        free(keep);
    }
    free(s.patch);
    free(s.plane);
    free(s.start);
    free(s.list);
    if (tested)
        *tested = s.tested;
    if (s.cancelled)
        return PD_ERR_CANCELLED;
    if (found < 0)
        return PD_ERR_NOMEM;
    if (found) {
        *ta = s.ta;
        *tb = s.tb;
        *at = s.at;
    }
    return PD_OK;
}
