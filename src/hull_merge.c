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
 * Each region is a disc; its boundary loop is walked from the triangles'
 * edges, and a loop vertex where the neighbouring facet does not change (a
 * point on an edge) is dropped, leaving the corners: vertices on >= 3 facets. */
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include "diag.h"
#include "hull_internal.h"
#include "posedrop/tolerances.h"
#include "vec3.h"

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
                acc = trial;
                m->reg[u] = r;
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
        for (int i = start + verified; i < end; i++)
            m->reg[m->order[i]] = -1;
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
    *normal = n;
    *offset = v3_dot(n, v3_add(acc.ref, c));
    return end;
}

pd_status pd_hull_merge(const pd_vec3 *pts, const pd_trihull *th, pd_hull *h, pd_diag *diag)
{
    int nt = th->ntris, npts = 0;
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            if (th->tri[t][k] >= npts)
                npts = th->tri[t][k] + 1;
    merger m = {pts, th, PD_TOL_PLANE_REL * h->size, NULL, NULL};
    m.reg = malloc(sizeof *m.reg * (size_t)nt);
    m.order = malloc(sizeof *m.order * (size_t)nt);
    int *rstart = malloc(sizeof *rstart * (size_t)(nt + 1));
    pd_vec3 *rn = malloc(sizeof *rn * (size_t)nt);
    double *roff = malloc(sizeof *roff * (size_t)nt);
    int *out_edge = malloc(sizeof *out_edge * (size_t)npts);
    int *vid = malloc(sizeof *vid * (size_t)npts);
    int *loopv = NULL, *loopa = NULL;
    pd_status st = PD_OK;
    if (!m.reg || !m.order || !rstart || !rn || !roff || !out_edge || !vid) {
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
    float *quality = malloc(sizeof *quality * (size_t)nt);
    if (!quality) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory merging %d triangles", nt);
        goto done;
    }
    for (int t = 0; t < nt; t++) {
        const int *v = th->tri[t];
        pd_vec3 e0 = v3_sub(pts[v[1]], pts[v[0]]), e1 = v3_sub(pts[v[2]], pts[v[1]]),
                e2 = v3_sub(pts[v[0]], pts[v[2]]);
        double lmax = fmax(v3_dot(e0, e0), fmax(v3_dot(e1, e1), v3_dot(e2, e2)));
        /* |cross| / longest^2: scale-free, 0 for a degenerate triangle */
        quality[t] = (float)(v3_norm(v3_cross(e0, e1)) / lmax);
    }
    static const float pass_quality[] = {0.1f, 1e-4f, 1e-8f, -1.0f};
    int nreg = 0, end = 0;
    for (int pass = 0; pass < 4; pass++)
        for (int t = 0; t < nt; t++) {
            if (m.reg[t] != -1 || !(quality[t] >= pass_quality[pass]))
                continue;
            rstart[nreg] = end;
            m.order[end] = t;
            end = grow_region(&m, nreg, end, &rn[nreg], &roff[nreg]);
            nreg++;
        }
    free(quality);
    rstart[nreg] = end;

    /* Boundary loops -> corners. Loops have at most 3 nt edges in total. */
    loopv = malloc(sizeof *loopv * (size_t)(3 * nt));
    loopa = malloc(sizeof *loopa * (size_t)(3 * nt));
    h->facet_start = malloc(sizeof *h->facet_start * (size_t)(nreg + 1));
    if (!loopv || !loopa || !h->facet_start) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory building facet loops");
        goto done;
    }
    for (int i = 0; i < npts; i++) {
        out_edge[i] = -1;
        vid[i] = -1;
    }
    int nloop = 0, nverts = 0;
    for (int r = 0; r < nreg; r++) {
        int nb_edges = 0, first = -1;
        for (int i = rstart[r]; i < rstart[r + 1]; i++) {
            int t = m.order[i];
            for (int e = 0; e < 3; e++)
                if (m.reg[th->nb[t][e]] != r) {
                    out_edge[th->tri[t][e]] = 3 * t + e;
                    nb_edges++;
                    if (first < 0)
                        first = 3 * t + e;
                }
        }
        /* Walk the loop; the corner before edge i is where the neighbour
         * region changes from edge i-1 to edge i. */
        int walked = 0, he = first, kstart = nloop;
        int *seq = loopa + nloop; /* scratch: neighbour per walked edge */
        int *sv = loopv + nloop;  /* start vertex per walked edge */
        do {
            int t = he / 3, e = he % 3;
            if (walked >= nb_edges)
                break;
            sv[walked] = th->tri[t][e];
            seq[walked] = m.reg[th->nb[t][e]];
            walked++;
            he = out_edge[th->tri[t][(e + 1) % 3]];
        } while (he != first && he >= 0);
        for (int i = rstart[r]; i < rstart[r + 1]; i++) {
            int t = m.order[i];
            for (int e = 0; e < 3; e++)
                out_edge[th->tri[t][e]] = -1;
        }
        if (walked != nb_edges || he != first) {
            st = pd_fail(diag, PD_ERR_INTERNAL,
                         "convex hull: merged facet %d is not a disc (boundary %d edges, loop %d)", r, nb_edges,
                         walked);
            goto done;
        }
        int prev_adj = seq[walked - 1];
        int k = 0;
        for (int i = 0; i < walked; i++) {
            if (seq[i] != prev_adj) {
                /* compact in place: k <= i, so no unread entry is overwritten */
                sv[k] = sv[i];
                seq[k] = seq[i];
                k++;
            }
            prev_adj = seq[i];
        }
        if (k < 3) {
            /* Only a rim where both sides lie within the tolerance of one
             * plane leaves a facet with its whole boundary on one
             * neighbour: the points are flat to within the tolerance there. */
            st = pd_fail(diag, PD_ERR_COPLANAR,
                         "convex hull: facet %d has %d corners: the points form a sheet thinner than %.3g "
                         "(tolerance %.3g of the size %.3g) along its rim",
                         r, k, m.tol, PD_TOL_PLANE_REL, h->size);
            goto done;
        }
        for (int i = 0; i < k; i++)
            if (vid[sv[i]] < 0)
                vid[sv[i]] = nverts++;
        h->facet_start[r] = kstart;
        nloop += k;
    }
    h->facet_start[nreg] = nloop;

    h->nfacets = nreg;
    h->nverts = nverts;
    h->normal = malloc(sizeof *h->normal * (size_t)nreg);
    h->offset = malloc(sizeof *h->offset * (size_t)nreg);
    h->facet_vert = malloc(sizeof *h->facet_vert * (size_t)nloop);
    h->facet_adj = malloc(sizeof *h->facet_adj * (size_t)nloop);
    h->verts = malloc(sizeof *h->verts * (size_t)nverts);
    h->vert_source = malloc(sizeof *h->vert_source * (size_t)nverts);
    if (!h->normal || !h->offset || !h->facet_vert || !h->facet_adj || !h->verts || !h->vert_source) {
        st = pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory for %d facets", nreg);
        goto done;
    }
    for (int i = 0; i < nloop; i++) {
        int src = loopv[i];
        h->facet_vert[i] = vid[src];
        h->facet_adj[i] = loopa[i];
        h->verts[vid[src]] = pts[src];
        h->vert_source[vid[src]] = src;
    }
    for (int r = 0; r < nreg; r++) {
        h->normal[r] = rn[r];
        h->offset[r] = roff[r];
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
done:
    free(m.reg);
    free(m.order);
    free(rstart);
    free(rn);
    free(roff);
    free(out_edge);
    free(vid);
    free(loopv);
    free(loopa);
    return st;
}
