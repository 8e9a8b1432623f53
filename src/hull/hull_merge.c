/* hull_merge.c: coplanar hull triangles -> polygonal facets.
 *
 * Regions grow from a seed triangle across shared edges. A neighbour joins
 * when, with the region's plane refitted to include it, its vertices lie
 * within PD_TOL_PLANE_REL * size of that plane. The refit (area-weighted
 * normal and centroid, accumulated in coordinates relative to the seed) makes
 * the plane better as the region grows, so a sliver seed does not decide
 * alone. Because the plane moves, earlier vertices can drift out: the whole
 * region is re-verified each time it doubles and when it stops growing; if a
 * verification fails the region rolls back to its last verified state and
 * continues verifying every vertex at every step. So every vertex of a facet
 * is within tolerance of its plane, and a finely tessellated curve cannot
 * creep into one non-planar facet.
 *
 * A facet must be a disc: one boundary loop through distinct vertices. On a
 * tessellated curved surface the plane test alone happily grows a ring around
 * a patch that bulges out of the plane (an annulus), or closes a region onto
 * itself at one vertex. So a triangle joins only if it keeps the region a
 * disc (see keeps_disc); each state of a region, including every state a
 * rollback returns to, is then a disc.
 *
 * Each region's boundary loop is walked from the triangles' edges, and a loop
 * vertex where the neighbouring facet does not change (a point on an edge) is
 * dropped, leaving the corners: vertices on >= 3 facets. Discs can still leave
 * a facet with fewer than 3 corners (a region wrapping around a vertex leaves
 * the one triangle it could not take bordered by it on two sides, or two
 * curved regions meet along two runs around a lens between them), or with
 * corners that, without the dropped points between them, no longer turn
 * counter-clockwise (a long curved region with few corners). Such a facet,
 * and in the last resort the regions around it, is dissolved into its single
 * triangles, which is always valid: the exact triangulation is a
 * convex polytope, and a triangle whose neighbours are all single triangles
 * has three corners. Each repair pass dissolves at least one region of two or
 * more triangles, so the repair ends, in practice after one or two passes. */
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "hull/hull_internal.h"
#include "posedrop/tolerances.h"
#include "base/vec3.h"

typedef struct {
    pd_vec3 ref;  /* origin of the relative coordinates */
    pd_vec3 s;    /* sum of (b-a) x (c-a): twice the area vector */
    double w;     /* sum of |(b-a) x (c-a)| */
    pd_vec3 cw;   /* sum of |(b-a) x (c-a)| * centroid, relative to ref */
    double uv;    /* sum of |b-a| |c-a|: scale of the round-off of s */
} plane_acc;

typedef struct {
    const pd_vec3 *p;
    const pd_trihull *th;
    double tol;
    int *reg;
    int *order;
    int *vcnt; /* per point: triangles of the growing region that use it */
    long disc_rejects;
} merger;

static void tri_terms(const merger *m, int t, pd_vec3 ref, pd_vec3 *cr, double *w, pd_vec3 *cw, double *uv)
{
    const int *v = m->th->tri[t];
    pd_vec3 a = v3_sub(m->p[v[0]], ref), b = v3_sub(m->p[v[1]], ref), c = v3_sub(m->p[v[2]], ref);
    *cr = v3_cross(v3_sub(b, a), v3_sub(c, a));
    *uv = v3_norm(v3_sub(b, a)) * v3_norm(v3_sub(c, a));
    *w = v3_norm(*cr);
    *cw = v3_scale(v3_add(v3_add(a, b), c), *w / 3.0);
}

/* Cross products whose length is below this multiple of eps |u| |v| (u, v
 * its edge vectors) have round-off comparable to their size: their direction
 * says nothing. 16 roundings cover the subtractions and products. */
#define SLIVER_DIRECTION_EPS (16.0 * DBL_EPSILON)

/* A triangle whose normal reliably points against the region's is across a
 * fold (a rim where both sides lie within the tolerance of one plane), never
 * part of the same facet; letting it in would cancel the area vector. Slivers
 * (and regions) whose computed normal is round-off are not judged by it. */
static int faces_against(const merger *m, int t, const plane_acc *acc)
{
    const int *v = m->th->tri[t];
    pd_vec3 a = m->p[v[0]];
    pd_vec3 u = v3_sub(m->p[v[1]], a), w = v3_sub(m->p[v[2]], a);
    pd_vec3 cr = v3_cross(u, w);
    if (v3_norm(cr) <= SLIVER_DIRECTION_EPS * v3_norm(u) * v3_norm(w) ||
        v3_norm(acc->s) <= SLIVER_DIRECTION_EPS * acc->uv)
        return 0;
    return v3_dot(cr, acc->s) < 0.0;
}

static void acc_add(const merger *m, plane_acc *acc, int t)
{
    pd_vec3 cr, cw;
    double w, uv;
    tri_terms(m, t, acc->ref, &cr, &w, &cw, &uv);
    acc->uv += uv;
    acc->s = v3_add(acc->s, cr);
    acc->w += w;
    acc->cw = v3_add(acc->cw, cw);
}

/* Unit normal and a point (relative to ref) of the accumulated plane. */
static void acc_plane(const plane_acc *acc, pd_vec3 *n, pd_vec3 *c)
{
    *n = v3_unit(acc->s);
    *c = v3_scale(acc->cw, 1.0 / acc->w);
}

static int tri_within(const merger *m, int t, pd_vec3 ref, pd_vec3 n, pd_vec3 c)
{
    for (int k = 0; k < 3; k++) {
        double d = v3_dot(n, v3_sub(v3_sub(m->p[m->th->tri[t][k]], ref), c));
        if (!(fabs(d) <= m->tol))
            return 0;
    }
    return 1;
}

static int region_within(const merger *m, int start, int end, pd_vec3 ref, pd_vec3 n, pd_vec3 c)
{
    for (int i = start; i < end; i++)
        if (!tri_within(m, m->order[i], ref, n, c))
            return 0;
    return 1;
}

/* Whether region r (a disc) stays a disc with triangle u added. u touches
 * the region along 1, 2 or 3 of its edges. Along 2: they meet at a vertex
 * the region's boundary passes through once, so u fills the notch there and
 * the boundary stays one simple loop. Along 1: the loop stays simple unless
 * u's far vertex is already on the region (it can only be on its boundary:
 * all triangles around an interior vertex are in the region), which would
 * pinch the loop there or close a ring. Along 3: u would close the surface. */
static int keeps_disc(const merger *m, int u, int r)
{
    int shared = 0, edge = -1;
    for (int j = 0; j < 3; j++)
        if (m->reg[m->th->nb[u][j]] == r) {
            shared++;
            edge = j;
        }
    if (shared == 2)
        return 1;
    return shared == 1 && m->vcnt[m->th->tri[u][(edge + 2) % 3]] == 0;
}

static void count_verts(merger *m, int t, int delta)
{
    for (int k = 0; k < 3; k++)
        m->vcnt[m->th->tri[t][k]] += delta;
}

/* Grows region r from seed (order[start] == seed on entry); returns its end
 * in order[] and the region's plane. */
static int grow_region(merger *m, int r, int start, pd_vec3 *normal, double *offset)
{
    const pd_trihull *th = m->th;
    int seed = m->order[start];
    plane_acc acc;
    memset(&acc, 0, sizeof acc);
    acc.ref = m->p[th->tri[seed][0]];
    acc_add(m, &acc, seed);
    m->reg[seed] = r;
    count_verts(m, seed, 1);
    int end = start + 1, head = start, verified = 1, strict = 0;
    pd_vec3 n, c;
    for (;;) {
        int failed = 0;
        while (head < end && !failed) {
            int t = m->order[head++];
            for (int e = 0; e < 3; e++) {
                int u = th->nb[t][e];
                if (m->reg[u] != -1)
                    continue;
                plane_acc trial = acc;
                acc_add(m, &trial, u);
                if (faces_against(m, u, &acc))
                    continue;
                acc_plane(&trial, &n, &c);
                if (!tri_within(m, u, acc.ref, n, c))
                    continue;
                if (strict && !region_within(m, start, end, acc.ref, n, c))
                    continue;
                /* Last, so that the count is of triangles only the topology
                 * kept out. A rejected triangle is looked at again from each
                 * triangle that joins next to it, and joins once it fills a
                 * notch. */
                if (!keeps_disc(m, u, r)) {
                    m->disc_rejects++;
                    continue;
                }
                acc = trial;
                m->reg[u] = r;
                count_verts(m, u, 1);
                m->order[end++] = u;
                if (strict) {
                    verified = end - start;
                } else if (end - start >= 2 * verified) {
                    if (!region_within(m, start, end, acc.ref, n, c)) {
                        failed = 1;
                        break;
                    }
                    verified = end - start;
                }
            }
        }
        acc_plane(&acc, &n, &c);
        if (!failed && (end - start == verified || region_within(m, start, end, acc.ref, n, c)))
            break;
        /* Roll back to the last verified state and go on verifying every
         * vertex at every step (only reached on curved, finely tessellated
         * surfaces, where regions stay small). */
        for (int i = start + verified; i < end; i++) {
            m->reg[m->order[i]] = -1;
            count_verts(m, m->order[i], -1);
        }
        end = start + verified;
        memset(&acc.s, 0, sizeof acc.s);
        acc.w = 0.0;
        acc.uv = 0.0;
        memset(&acc.cw, 0, sizeof acc.cw);
        for (int i = start; i < end; i++)
            acc_add(m, &acc, m->order[i]);
        head = start;
        strict = 1;
    }
    for (int i = start; i < end; i++)
        count_verts(m, m->order[i], -1);
    *normal = n;
    *offset = v3_dot(n, v3_add(acc.ref, c));
    return end;
}

/* Regions as contiguous runs of order[]: region r is order[start[r] ..
 * start[r + 1]), with plane normal[r], offset[r]. */
typedef struct {
    int n;
    int *start;
    pd_vec3 *normal;
    double *offset;
} regions;

/* Scratch of the loop walk, per input point and per loop edge. */
typedef struct {
    int *out_edge; /* per point: boundary half-edge 3 t + e leaving it, or -1 */
    int *loopv;    /* start vertex (input index) of each kept loop edge */
    int *loopa;    /* region across it */
    int *facet_start;
    char *bad;     /* per region: not a disc, or fewer than 3 corners */
} loops;

/* Walks every region's boundary loop and keeps its corners. Returns the
 * number of regions marked bad (their loop entries are not kept). */
static int build_loops(const merger *m, const regions *rg, loops *lp, int *nloop_out)
{
    const pd_trihull *th = m->th;
    int nloop = 0, nbad = 0;
    for (int r = 0; r < rg->n; r++) {
        int nb_edges = 0, first = -1;
        lp->bad[r] = 0;
        lp->facet_start[r] = nloop;
        for (int i = rg->start[r]; i < rg->start[r + 1]; i++) {
            int t = m->order[i];
            for (int e = 0; e < 3; e++)
                if (m->reg[th->nb[t][e]] != r) {
                    lp->out_edge[th->tri[t][e]] = 3 * t + e;
                    nb_edges++;
                    if (first < 0)
                        first = 3 * t + e;
                }
        }
        /* Walk the loop; the corner before edge i is where the neighbour
         * region changes from edge i-1 to edge i. A vertex the boundary
         * passes twice keeps only one leaving edge in out_edge, so the walk
         * then closes early or runs into a reset entry: not a disc. */
        int walked = 0, he = first;
        int *seq = lp->loopa + nloop; /* scratch: neighbour per walked edge */
        int *sv = lp->loopv + nloop;  /* start vertex per walked edge */
        while (he >= 0 && walked < nb_edges) {
            int t = he / 3, e = he % 3;
            sv[walked] = th->tri[t][e];
            seq[walked] = m->reg[th->nb[t][e]];
            walked++;
            he = lp->out_edge[th->tri[t][(e + 1) % 3]];
            if (he == first)
                break;
        }
        for (int i = rg->start[r]; i < rg->start[r + 1]; i++) {
            int t = m->order[i];
            for (int e = 0; e < 3; e++)
                lp->out_edge[th->tri[t][e]] = -1;
        }
        int k = 0;
        if (walked == nb_edges && he == first) {
            int prev_adj = seq[walked - 1];
            for (int i = 0; i < walked; i++) {
                if (seq[i] != prev_adj) {
                    /* compact in place: k <= i, so no unread entry is overwritten */
                    sv[k] = sv[i];
                    seq[k] = seq[i];
                    k++;
                }
                prev_adj = seq[i];
            }
        }
        /* The corners alone must still turn counter-clockwise about the
         * facet's normal: a long curved region with few corners can fold its
         * corner polygon over (pd_hull_check asks the same). */
        pd_vec3 turn = v3(0, 0, 0);
        for (int i = 1; k >= 3 && i + 1 < k; i++)
            turn = v3_add(turn, v3_cross(v3_sub(m->p[sv[i]], m->p[sv[0]]), v3_sub(m->p[sv[i + 1]], m->p[sv[0]])));
        if (k < 3 || !(v3_dot(turn, rg->normal[r]) > 0.0)) {
            lp->bad[r] = 1;
            nbad++;
            continue;
        }
        nloop += k;
    }
    lp->facet_start[rg->n] = nloop;
    *nloop_out = nloop;
    return nbad;
}

/* Plane of the single triangle t. */
static void tri_plane(const merger *m, int t, pd_vec3 *n, double *offset)
{
    plane_acc acc;
    memset(&acc, 0, sizeof acc);
    acc.ref = m->p[m->th->tri[t][0]];
    acc_add(m, &acc, t);
    pd_vec3 c;
    acc_plane(&acc, n, &c);
    *offset = v3_dot(*n, v3_add(acc.ref, c));
}

/* Dissolves the bad regions into single triangles, and for a bad single
 * triangle the regions around it (one of them borders it on two edges, which
 * is why it lacks a corner). Regions keep their runs of order[], so only the
 * numbering changes; next receives the new regions. */
static void dissolve(merger *m, const regions *rg, const loops *lp, char *mark, regions *next, long *nregions,
                     long *ntris)
{
    const pd_trihull *th = m->th;
    for (int r = 0; r < rg->n; r++)
        mark[r] = 0;
    for (int r = 0; r < rg->n; r++) {
        if (!lp->bad[r])
            continue;
        mark[r] = 1;
        if (rg->start[r + 1] - rg->start[r] == 1) {
            int t = m->order[rg->start[r]];
            for (int e = 0; e < 3; e++)
                mark[m->reg[th->nb[t][e]]] = 1;
        }
    }
    int nr = 0;
    for (int r = 0; r < rg->n; r++) {
        int a = rg->start[r], b = rg->start[r + 1];
        if (!mark[r] || b - a == 1) {
            next->start[nr] = a;
            next->normal[nr] = rg->normal[r];
            next->offset[nr] = rg->offset[r];
            for (int i = a; i < b; i++)
                m->reg[m->order[i]] = nr;
            nr++;
            continue;
        }
        (*nregions)++;
        *ntris += b - a;
        for (int i = a; i < b; i++) {
            int t = m->order[i];
            next->start[nr] = i;
            tri_plane(m, t, &next->normal[nr], &next->offset[nr]);
            m->reg[t] = nr;
            nr++;
        }
    }
    next->start[nr] = rg->start[rg->n];
    next->n = nr;
}

pd_status pd_hull_merge(const pd_vec3 *pts, const pd_trihull *th, pd_hull *h, pd_hull_merge_stats *stats,
                        pd_diag *diag)
{
    int nt = th->ntris, npts = 0;
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            if (th->tri[t][k] >= npts)
                npts = th->tri[t][k] + 1;
    merger m = {pts, th, PD_TOL_PLANE_REL * h->size, NULL, NULL, NULL, 0};
    regions rg = {0, NULL, NULL, NULL}, alt = {0, NULL, NULL, NULL};
    loops lp = {NULL, NULL, NULL, NULL, NULL};
    char *mark = NULL;
    float *quality = NULL;
    long dissolved_regions = 0, dissolved_tris = 0;
    int passes = 0;
    m.reg = malloc(sizeof *m.reg * (size_t)nt);
    m.order = malloc(sizeof *m.order * (size_t)nt);
    m.vcnt = calloc((size_t)npts, sizeof *m.vcnt);
    rg.start = malloc(sizeof *rg.start * (size_t)(nt + 1));
    rg.normal = malloc(sizeof *rg.normal * (size_t)nt);
    rg.offset = malloc(sizeof *rg.offset * (size_t)nt);
    lp.out_edge = malloc(sizeof *lp.out_edge * (size_t)npts);
    quality = malloc(sizeof *quality * (size_t)nt);
    pd_status st = PD_OK;
    if (!m.reg || !m.order || !m.vcnt || !rg.start || !rg.normal || !rg.offset || !lp.out_edge || !quality) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory merging %d triangles", nt);
        goto done;
    }
    for (int t = 0; t < nt; t++)
        m.reg[t] = -1;
    /* Seeds by shape quality, best first, in a few passes of decreasing
     * threshold (an O(n) stand-in for sorting): a well-shaped triangle's
     * normal is accurate, a sliver's (three nearly collinear points) can be
     * off by radians, and a sliver seed among sliver neighbours would reject
     * them all and stay a facet of its own. Within a pass, by index, so the
     * order is deterministic. */
    for (int t = 0; t < nt; t++) {
        const int *v = th->tri[t];
        pd_vec3 e0 = v3_sub(pts[v[1]], pts[v[0]]), e1 = v3_sub(pts[v[2]], pts[v[1]]),
                e2 = v3_sub(pts[v[0]], pts[v[2]]);
        double lmax = fmax(v3_dot(e0, e0), fmax(v3_dot(e1, e1), v3_dot(e2, e2)));
        /* |cross| / longest^2: scale-free, 0 for a degenerate triangle */
        quality[t] = (float)(v3_norm(v3_cross(e0, e1)) / lmax);
    }
    static const float pass_quality[] = {0.1f, 1e-4f, 1e-8f, -1.0f};
    int end = 0;
    for (int pass = 0; pass < 4; pass++)
        for (int t = 0; t < nt; t++) {
            if (m.reg[t] != -1 || !(quality[t] >= pass_quality[pass]))
                continue;
            rg.start[rg.n] = end;
            m.order[end] = t;
            end = grow_region(&m, rg.n, end, &rg.normal[rg.n], &rg.offset[rg.n]);
            rg.n++;
        }
    rg.start[rg.n] = end;

    /* Boundary loops -> corners. Loops have at most 3 nt edges in total;
     * there are at most nt regions, however many are dissolved. */
    lp.loopv = malloc(sizeof *lp.loopv * (size_t)(3 * nt));
    lp.loopa = malloc(sizeof *lp.loopa * (size_t)(3 * nt));
    lp.facet_start = malloc(sizeof *lp.facet_start * (size_t)(nt + 1));
    lp.bad = malloc((size_t)nt);
    if (!lp.loopv || !lp.loopa || !lp.facet_start || !lp.bad) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory building facet loops");
        goto done;
    }
    for (int i = 0; i < npts; i++)
        lp.out_edge[i] = -1;
    int nloop = 0;
    while (build_loops(&m, &rg, &lp, &nloop) > 0) {
        if (!alt.start) {
            alt.start = malloc(sizeof *alt.start * (size_t)(nt + 1));
            alt.normal = malloc(sizeof *alt.normal * (size_t)nt);
            alt.offset = malloc(sizeof *alt.offset * (size_t)nt);
            mark = malloc((size_t)nt);
            if (!alt.start || !alt.normal || !alt.offset || !mark) {
                st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory repairing %d facets", rg.n);
                goto done;
            }
        }
        long before = dissolved_regions;
        dissolve(&m, &rg, &lp, mark, &alt, &dissolved_regions, &dissolved_tris);
        regions tmp = rg;
        rg = alt;
        alt = tmp;
        passes++;
        if (dissolved_regions == before) {
            /* Cannot happen: a bad region of one triangle has a neighbour
             * of two or more on two of its edges. Guards the loop. */
            st = pd_fail(diag, PD_ERR_INTERNAL, "convex hull: facet repair made no progress (%d facets)", rg.n);
            goto done;
        }
    }
    int nreg = rg.n;
    int *vid = lp.out_edge; /* free again: every entry is back to -1 */
    int nverts = 0;
    for (int i = 0; i < nloop; i++)
        if (vid[lp.loopv[i]] < 0)
            vid[lp.loopv[i]] = nverts++;

    h->nfacets = nreg;
    h->nverts = nverts;
    h->facet_start = malloc(sizeof *h->facet_start * (size_t)(nreg + 1));
    h->normal = malloc(sizeof *h->normal * (size_t)nreg);
    h->offset = malloc(sizeof *h->offset * (size_t)nreg);
    h->facet_vert = malloc(sizeof *h->facet_vert * (size_t)nloop);
    h->facet_adj = malloc(sizeof *h->facet_adj * (size_t)nloop);
    h->verts = malloc(sizeof *h->verts * (size_t)nverts);
    h->vert_source = malloc(sizeof *h->vert_source * (size_t)nverts);
    if (!h->facet_start || !h->normal || !h->offset || !h->facet_vert || !h->facet_adj || !h->verts ||
        !h->vert_source) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory for %d facets", nreg);
        goto done;
    }
    memcpy(h->facet_start, lp.facet_start, sizeof *h->facet_start * (size_t)(nreg + 1));
    for (int i = 0; i < nloop; i++) {
        int src = lp.loopv[i];
        h->facet_vert[i] = vid[src];
        h->facet_adj[i] = lp.loopa[i];
        h->verts[vid[src]] = pts[src];
        h->vert_source[vid[src]] = src;
    }
    for (int r = 0; r < nreg; r++) {
        h->normal[r] = rg.normal[r];
        h->offset[r] = rg.offset[r];
    }
    /* Volume of the triangulated hull (the exact hull of the input; merging
     * moves nothing by more than the tolerance) as tetrahedra from the
     * centroid of the corners, in coordinates relative to it. */
    pd_vec3 c = v3(0, 0, 0);
    for (int i = 0; i < nverts; i++)
        c = v3_add(c, v3_sub(h->verts[i], h->verts[0]));
    c = v3_add(h->verts[0], v3_scale(c, 1.0 / nverts));
    double vol = 0.0;
    for (int t = 0; t < nt; t++) {
        pd_vec3 a = v3_sub(pts[th->tri[t][0]], c), b = v3_sub(pts[th->tri[t][1]], c),
                d = v3_sub(pts[th->tri[t][2]], c);
        vol += v3_dot(a, v3_cross(b, d));
    }
    h->volume = vol / 6.0;
    if (stats) {
        stats->disc_rejects = m.disc_rejects;
        stats->dissolved_regions = dissolved_regions;
        stats->dissolved_triangles = dissolved_tris;
        stats->repair_passes = passes;
    }
done:
    free(m.reg);
    free(m.order);
    free(m.vcnt);
    free(quality);
    free(rg.start);
    free(rg.normal);
    free(rg.offset);
    free(alt.start);
    free(alt.normal);
    free(alt.offset);
    free(mark);
    free(lp.out_edge);
    free(lp.loopv);
    free(lp.loopa);
    free(lp.facet_start);
    free(lp.bad);
    return st;
}
