/* hull_tri.c: quickhull in 3-D on the exact orientation predicate.
 *
 * The hull grows from a tetrahedron. Every triangle keeps the input points
 * strictly outside it (its "outside set"); the point of a set furthest from
 * its triangle is certainly a vertex of the final hull, so it is added next:
 * the triangles that see it are removed, a cone of new triangles joins it to
 * the horizon, and the removed triangles' points are handed to the new ones or
 * dropped as inside. Visibility is decided by pd_orient3d, exactly, so the
 * surface stays closed and exactly convex for the double input; points
 * exactly on a triangle's plane are not outside. Distances only rank points
 * and are computed in floating point.
 *
 * Memory: triangles live in one growable array with a free list, and outside
 * sets are contiguous segments of one pool of point records (index plus
 * coordinates, so scanning a set streams through memory rather than jumping
 * around the input). Removed segments become garbage; the pool is compacted
 * when full. Nothing is allocated per triangle. */
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "hull/hull_internal.h"
#include "base/predicates.h"
#include "base/vec3.h"

typedef struct {
    int v[3];         /* counter-clockwise seen from outside */
    int nb[3];        /* across edge v[i] -> v[i+1] */
    pd_vec3 n;        /* (v1 - v0) x (v2 - v0), rounded: filter and ranking */
    pd_vec3 nperm;    /* its permanent, for the filter's error bound */
    size_t os;        /* outside set: pool[os .. os + oc) */
    int oc;
    int far;          /* offset in the set of its furthest point */
    int mark;         /* stamp of the visibility test that last saw it */
    int vis;          /* result of that test */
    int alive;
} qtri;

typedef struct {
    pd_vec3 p;
    int idx;
} opt;

typedef struct {
    const pd_vec3 *pts;
    qtri *t;
    int nt, capt, freelist;
    opt *pool;
    size_t npool, cappool, live; /* live: records in the sets of live triangles */
    opt *spare;                  /* the pool before the last compaction, reused */
    size_t capspare;
    opt *tmp;
    size_t captmp;
    int *asg;
    double *dist;
    int *list, caplist; /* visible triangles, then new triangles */
    int *hor, caphor;   /* horizon as (triangle, edge) pairs */
    int *stack, nstack, capstack;
    int *cone_at;       /* per input point: new triangle whose first edge starts there */
    int *cnt;
    int stamp;
    pd_cancel_flag *cancel; /* may be NULL */
} qhull;

/* Grows *arr (of element size sz) to hold at least need elements. */
static int grow(void **arr, int *cap, int need, size_t sz)
{
    if (need <= *cap)
        return 0;
    int nc = *cap ? *cap : 64;
    while (nc < need)
        nc = nc > (1 << 29) ? need : nc * 2;
    void *p = realloc(*arr, sz * (size_t)nc);
    if (!p)
        return -1;
    *arr = p;
    *cap = nc;
    return 0;
}

static int new_tri(qhull *q, int a, int b, int c)
{
    int id;
    if (q->freelist >= 0) {
        id = q->freelist;
        q->freelist = q->t[id].nb[0];
    } else {
        if (grow((void **)&q->t, &q->capt, q->nt + 1, sizeof *q->t))
            return -1;
        id = q->nt++;
    }
    qtri *t = &q->t[id];
    t->v[0] = a;
    t->v[1] = b;
    t->v[2] = c;
    t->nb[0] = t->nb[1] = t->nb[2] = -1;
    const pd_vec3 *pa = &q->pts[a], *pb = &q->pts[b], *pc = &q->pts[c];
    double ux = pb->x - pa->x, uy = pb->y - pa->y, uz = pb->z - pa->z;
    double vx = pc->x - pa->x, vy = pc->y - pa->y, vz = pc->z - pa->z;
    t->n.x = uy * vz - uz * vy;
    t->n.y = uz * vx - ux * vz;
    t->n.z = ux * vy - uy * vx;
    t->nperm.x = fabs(uy * vz) + fabs(uz * vy);
    t->nperm.y = fabs(uz * vx) + fabs(ux * vz);
    t->nperm.z = fabs(ux * vy) + fabs(uy * vx);
    t->os = 0;
    t->oc = t->far = 0;
    t->mark = 0;
    t->vis = 0;
    t->alive = 1;
    return id;
}

static void free_tri(qhull *q, int id)
{
    q->t[id].alive = 0;
    q->t[id].oc = 0;
    q->t[id].nb[0] = q->freelist;
    q->freelist = id;
}

/* Makes room for need more records at the end of the pool, compacting the
 * sets of live triangles into the other of two pools when it is full. The
 * new capacity is at least the initial one (the point count), so
 * compaction, which walks every triangle, happens only O(log n) times over
 * a run. The two pools take turns: a fresh one each time cost a page fault
 * per 4 kB written. */
static int pool_reserve(qhull *q, size_t need, size_t mincap)
{
    if (q->npool + need <= q->cappool)
        return 0;
    size_t cap = 2 * (q->live + need);
    if (cap < mincap)
        cap = mincap;
    opt *np = q->spare;
    if (q->capspare >= cap) {
        cap = q->capspare;
    } else {
        free(q->spare);
        q->spare = NULL;
        q->capspare = 0;
        np = malloc(sizeof *np * cap);
        if (!np)
            return -1;
    }
    size_t k = 0;
    for (int i = 0; i < q->nt; i++) {
        qtri *t = &q->t[i];
        if (!t->alive || t->oc == 0)
            continue;
        memcpy(np + k, q->pool + t->os, sizeof *np * (size_t)t->oc);
        t->os = k;
        k += (size_t)t->oc;
    }
    q->spare = q->pool;
    q->capspare = q->cappool;
    q->pool = np;
    q->npool = k;
    q->cappool = cap;
    return 0;
}

/* Hands the m records of q->tmp to the nnew triangles q->list[first ..]: each
 * goes to the first triangle it is strictly outside of, or is dropped as
 * inside the hull. Returns -1 when out of memory, -3 when q->cancel is found
 * set (read every 4,096 records: the first calls share out nearly all the
 * points, a tenth of a second each on a million). */
static int distribute(qhull *q, size_t m, int first, int nnew, size_t mincap)
{
    const int *nf = q->list + first;
    memset(q->cnt, 0, sizeof *q->cnt * (size_t)nnew);
    int last = 0; /* consecutive points tend to be outside the same triangle */
    size_t assigned = 0;
    for (size_t i = 0; i < m; i++) {
        if (q->cancel && i % 4096 == 4095 && atomic_load_explicit(q->cancel, memory_order_relaxed))
            return -3;
        const opt *r = &q->tmp[i];
        q->asg[i] = -1;
        for (int k = 0; k < nnew; k++) {
            int j = last + k < nnew ? last + k : last + k - nnew;
            const qtri *t = &q->t[nf[j]];
            const pd_vec3 *a = &q->pts[t->v[0]];
            if (pd_orient3d_plane(&t->n, &t->nperm, a, &q->pts[t->v[1]], &q->pts[t->v[2]], &r->p) > 0) {
                q->asg[i] = j;
                q->dist[i] = v3_dot(t->n, v3_sub(r->p, *a));
                q->cnt[j]++;
                assigned++;
                last = j;
                break;
            }
        }
    }
    if (pool_reserve(q, assigned, mincap))
        return -1;
    /* Segments laid out in order of the new triangles. */
    size_t pos = q->npool;
    for (int j = 0; j < nnew; j++) {
        qtri *t = &q->t[nf[j]];
        t->os = pos;
        t->oc = 0;
        t->far = 0;
        pos += (size_t)q->cnt[j];
    }
    double *best = q->dist + m; /* scratch: best distance per new triangle */
    for (size_t i = 0; i < m; i++) {
        int j = q->asg[i];
        if (j < 0)
            continue;
        qtri *t = &q->t[nf[j]];
        if (t->oc == 0 || q->dist[i] > best[j]) {
            best[j] = q->dist[i];
            t->far = t->oc;
        }
        q->pool[t->os + t->oc++] = q->tmp[i];
    }
    q->npool = pos;
    q->live += assigned;
    for (int j = 0; j < nnew; j++)
        if (q->t[nf[j]].oc > 0) {
            if (grow((void **)&q->stack, &q->capstack, q->nstack + 1, sizeof *q->stack))
                return -1;
            q->stack[q->nstack++] = nf[j];
        }
    return 0;
}

/* Room for m records in tmp (and the per-record scratch arrays). */
static int tmp_reserve(qhull *q, size_t m, int nnew)
{
    size_t need = m + (size_t)nnew;
    if (need <= q->captmp)
        return 0;
    size_t cap = need + need / 2;
    opt *t = realloc(q->tmp, sizeof *t * cap);
    if (!t)
        return -1;
    q->tmp = t;
    int *a = realloc(q->asg, sizeof *a * cap);
    if (!a)
        return -1;
    q->asg = a;
    double *d = realloc(q->dist, sizeof *d * cap);
    if (!d)
        return -1;
    q->dist = d;
    int *c = realloc(q->cnt, sizeof *c * cap);
    if (!c)
        return -1;
    q->cnt = c;
    q->captmp = cap;
    return 0;
}

/* Index of the edge b -> a in triangle t (the twin of a -> b). */
static int twin_edge(const qtri *t, int a, int b)
{
    for (int j = 0; j < 3; j++)
        if (t->v[j] == b && t->v[(j + 1) % 3] == a)
            return j;
    return -1;
}

enum { HULL_POLL_EVERY = 16 };

/* Adds the furthest point of triangle f to the hull. */
static int add_point(qhull *q, int f, size_t mincap)
{
    opt apex = q->pool[q->t[f].os + q->t[f].far];
    q->stamp++;
    /* Visible triangles: breadth-first from f over triangles that strictly
     * see the apex; they form a disc whose boundary is the horizon. */
    int nvis = 0, nhor = 0;
    if (grow((void **)&q->list, &q->caplist, 1, sizeof *q->list))
        return -1;
    q->list[nvis++] = f;
    q->t[f].mark = q->stamp;
    q->t[f].vis = 1;
    for (int i = 0; i < nvis; i++) {
        int g = q->list[i];
        for (int e = 0; e < 3; e++) {
            int h = q->t[g].nb[e];
            qtri *th = &q->t[h];
            if (th->mark != q->stamp) {
                th->mark = q->stamp;
                th->vis = pd_orient3d_plane(&th->n, &th->nperm, &q->pts[th->v[0]], &q->pts[th->v[1]],
                                            &q->pts[th->v[2]], &apex.p) > 0;
                if (th->vis) {
                    if (grow((void **)&q->list, &q->caplist, nvis + 1, sizeof *q->list))
                        return -1;
                    q->list[nvis++] = h;
                }
            }
            if (!th->vis) {
                if (grow((void **)&q->hor, &q->caphor, 2 * nhor + 2, sizeof *q->hor))
                    return -1;
                q->hor[2 * nhor] = g;
                q->hor[2 * nhor + 1] = e;
                nhor++;
            }
        }
    }
    /* The cone: one new triangle (a, b, apex) per horizon edge a -> b, with
     * the orientation the visible triangle gave that edge. */
    if (grow((void **)&q->list, &q->caplist, nvis + nhor, sizeof *q->list))
        return -1;
    for (int i = 0; i < nhor; i++) {
        int g = q->hor[2 * i], e = q->hor[2 * i + 1];
        int a = q->t[g].v[e], b = q->t[g].v[(e + 1) % 3], h = q->t[g].nb[e];
        int nt = new_tri(q, a, b, apex.idx);
        if (nt < 0)
            return -1;
        int j = twin_edge(&q->t[h], a, b);
        if (j < 0)
            return -2;
        q->t[h].nb[j] = nt;
        q->t[nt].nb[0] = h;
        q->cone_at[a] = nt;
        q->list[nvis + i] = nt;
    }
    for (int i = 0; i < nhor; i++) {
        int nt = q->list[nvis + i];
        int next = q->cone_at[q->t[nt].v[1]];
        q->t[nt].nb[1] = next;
        q->t[next].nb[2] = nt;
    }
    /* Move the visible triangles' points (but the apex) to scratch, retire
     * the triangles, and hand the points to the cone. */
    size_t m = 0;
    for (int i = 0; i < nvis; i++)
        m += (size_t)q->t[q->list[i]].oc;
    if (tmp_reserve(q, m, nhor))
        return -1;
    m = 0;
    for (int i = 0; i < nvis; i++) {
        qtri *t = &q->t[q->list[i]];
        for (int k = 0; k < t->oc; k++) {
            const opt *r = &q->pool[t->os + k];
            if (r->idx != apex.idx)
                q->tmp[m++] = *r;
        }
        q->live -= (size_t)t->oc;
        free_tri(q, q->list[i]);
    }
    return distribute(q, m, nvis, nhor, mincap);
}

pd_status pd_trihull_build(const pd_vec3 *pts, int npts, const int seed[4], pd_cancel_flag *cancel,
                           pd_trihull *out, pd_diag *diag)
{
    qhull q;
    memset(&q, 0, sizeof q);
    q.pts = pts;
    q.freelist = -1;
    q.cancel = cancel;
    int rc = -1;
    size_t mincap = (size_t)npts + 16;
    q.cone_at = malloc(sizeof *q.cone_at * (size_t)npts);
    if (!q.cone_at || tmp_reserve(&q, (size_t)npts, 4))
        goto done;
    /* Tetrahedron, oriented so the fourth seed is inside every face. */
    int s[4] = {seed[0], seed[1], seed[2], seed[3]};
    if (pd_orient3d(&pts[s[0]], &pts[s[1]], &pts[s[2]], &pts[s[3]]) > 0) {
        int tmp = s[1];
        s[1] = s[2];
        s[2] = tmp;
    }
    static const int faces[4][3] = {{0, 1, 2}, {0, 3, 1}, {1, 3, 2}, {0, 2, 3}};
    if (grow((void **)&q.list, &q.caplist, 4, sizeof *q.list))
        goto done;
    for (int f = 0; f < 4; f++) {
        q.list[f] = new_tri(&q, s[faces[f][0]], s[faces[f][1]], s[faces[f][2]]);
        if (q.list[f] < 0)
            goto done;
    }
    for (int f = 0; f < 4; f++)
        for (int e = 0; e < 3; e++) {
            int a = q.t[f].v[e], b = q.t[f].v[(e + 1) % 3];
            for (int g = 0; g < 4; g++)
                if (g != f && twin_edge(&q.t[g], a, b) >= 0)
                    q.t[f].nb[e] = g;
        }
    size_t m = 0;
    for (int i = 0; i < npts; i++)
        if (i != s[0] && i != s[1] && i != s[2] && i != s[3]) {
            q.tmp[m].p = pts[i];
            q.tmp[m].idx = i;
            m++;
        }
    rc = distribute(&q, m, 0, 4, mincap);
    /* The flag read every HULL_POLL_EVERY points added: the first ones
     * share out almost all the points among their new triangles, so a
     * thousand of them, the first interval tried, took over a second of a
     * 2-million-triangle sphere's hull. */
    for (unsigned added = 0; rc == 0 && q.nstack > 0;) {
        int f = q.stack[--q.nstack];
        if (q.t[f].alive && q.t[f].oc > 0) {
            rc = add_point(&q, f, mincap);
            if (cancel && ++added % HULL_POLL_EVERY == 0 &&
                atomic_load_explicit(cancel, memory_order_relaxed))
                rc = -3;
        }
    }
    if (rc == 0) {
        /* Compact the live triangles into the output. */
        int *tmap = malloc(sizeof *tmap * (size_t)(q.nt > 0 ? q.nt : 1));
        int k = 0;
        if (!tmap) {
            rc = -1;
            goto done;
        }
        for (int i = 0; i < q.nt; i++)
            tmap[i] = q.t[i].alive ? k++ : -1;
        out->ntris = k;
        out->tri = malloc(sizeof *out->tri * (size_t)k);
        out->nb = malloc(sizeof *out->nb * (size_t)k);
        if (!out->tri || !out->nb) {
            free(tmap);
            pd_trihull_free(out);
            rc = -1;
            goto done;
        }
        for (int i = 0; i < q.nt; i++)
            if (q.t[i].alive)
                for (int e = 0; e < 3; e++) {
                    out->tri[tmap[i]][e] = q.t[i].v[e];
                    out->nb[tmap[i]][e] = tmap[q.t[i].nb[e]];
                }
        free(tmap);
    }
done:
    free(q.t);
    free(q.pool);
    free(q.spare);
    free(q.tmp);
    free(q.asg);
    free(q.dist);
    free(q.list);
    free(q.hor);
    free(q.stack);
    free(q.cone_at);
    free(q.cnt);
    if (rc == -3)
        return pd_fail(diag, PD_ERR_CANCELLED, "convex hull: cancelled");
    if (rc == -2)
        return pd_fail(diag, PD_ERR_INTERNAL, "convex hull: horizon edge without a twin (corrupt adjacency)");
    if (rc != 0)
        return pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory building the triangulated hull of %d points", npts);
    return PD_OK;
}

void pd_trihull_free(pd_trihull *th)
{
    free(th->tri);
    free(th->nb);
    th->tri = NULL;
    th->nb = NULL;
    th->ntris = 0;
}
