/* hull.c: pd_hull_build and pd_hull_free.
 *
 * Degenerate input is classified before any hull is attempted, so that a flat
 * or linear point set gets a status naming it (and the extent that decided)
 * rather than a failure deep inside quickhull. The same pass finds the
 * starting tetrahedron: two far-apart extreme points, the point furthest from
 * their line and the point furthest from the plane of the three. Those
 * distances are exactly the ones compared with the tolerance, so a set that
 * passes has a tetrahedron of height above PD_TOL_PLANE_REL * size, far above
 * round-off, and its orientation is certainly nonzero. */
#include <stdlib.h>
#include "base/fail.h"
#include "hull/hull_internal.h"
#include "posedrop/tolerances.h"
#include "base/predicates.h"
#include "base/size_range.h"
#include "base/vec3.h"

/* Classifies pts and picks the seed tetrahedron; sets *size. */
static pd_status classify(const pd_vec3 *p, int n, int seed[4], double *size, pd_diag *diag)
{
    if (n < 4)
        return pd_fail(diag, PD_ERR_TOO_FEW_POINTS, "convex hull: %d points, need at least 4", n);
    for (int i = 0; i < n; i++)
        if (!v3_isfinite(p[i]))
            return pd_fail(diag, PD_ERR_NONFINITE, "convex hull: point %d has a non-finite coordinate", i);
    /* Extreme points along the axes: ext[2k] minimum, ext[2k+1] maximum. */
    int ext[6] = {0, 0, 0, 0, 0, 0};
    for (int i = 1; i < n; i++) {
        if (p[i].x < p[ext[0]].x)
            ext[0] = i;
        if (p[i].x > p[ext[1]].x)
            ext[1] = i;
        if (p[i].y < p[ext[2]].y)
            ext[2] = i;
        if (p[i].y > p[ext[3]].y)
            ext[3] = i;
        if (p[i].z < p[ext[4]].z)
            ext[4] = i;
        if (p[i].z > p[ext[5]].z)
            ext[5] = i;
    }
    pd_vec3 lo = v3(p[ext[0]].x, p[ext[2]].y, p[ext[4]].z), hi = v3(p[ext[1]].x, p[ext[3]].y, p[ext[5]].z);
    pd_status st = pd_size_check(lo, hi, "convex hull: ", diag);
    if (st != PD_OK)
        return st;
    double L = v3_dist(lo, hi);
    *size = L;
    if (L == 0.0)
        return pd_fail(diag, PD_ERR_COLOCATED, "convex hull: all %d points coincide", n);
    double tol = PD_TOL_PLANE_REL * L;
    /* The farthest pair among the six extremes spans at least L / sqrt(3). */
    int a = ext[0], b = ext[1];
    double best = -1.0;
    for (int i = 0; i < 6; i++)
        for (int j = i + 1; j < 6; j++) {
            double d = v3_dist(p[ext[i]], p[ext[j]]);
            if (d > best) {
                best = d;
                a = ext[i];
                b = ext[j];
            }
        }
    pd_vec3 dir = v3_unit(v3_sub(p[b], p[a]));
    int c = a;
    double dline = 0.0;
    for (int i = 0; i < n; i++) {
        double d = v3_norm(v3_cross(v3_sub(p[i], p[a]), dir));
        if (d > dline) {
            dline = d;
            c = i;
        }
    }
    if (dline <= tol)
        return pd_fail(diag, PD_ERR_COLLINEAR,
                       "convex hull: all %d points lie within %.3g of a line (%.3g of the size %.3g; "
                       "tolerance %.3g)", n, dline, dline / L, L, PD_TOL_PLANE_REL);
    pd_vec3 nrm = v3_unit(v3_cross(v3_sub(p[b], p[a]), v3_sub(p[c], p[a])));
    int d = a;
    double dplane = 0.0;
    for (int i = 0; i < n; i++) {
        double s = fabs(v3_dot(nrm, v3_sub(p[i], p[a])));
        if (s > dplane) {
            dplane = s;
            d = i;
        }
    }
    if (dplane <= tol)
        return pd_fail(diag, PD_ERR_COPLANAR,
                       "convex hull: all %d points lie within %.3g of a plane (%.3g of the size %.3g; "
                       "tolerance %.3g): no volume", n, dplane, dplane / L, L, PD_TOL_PLANE_REL);
    if (pd_orient3d(&p[a], &p[b], &p[c], &p[d]) == 0)
        return pd_fail(diag, PD_ERR_INTERNAL, "convex hull: seed tetrahedron is flat despite height %.3g", dplane);
    seed[0] = a;
    seed[1] = b;
    seed[2] = c;
    seed[3] = d;
    return PD_OK;
}

pd_status pd_hull_build(const pd_vec3 *pts, int npts, pd_hull **hull, pd_diag *diag)
{
    return pd_hull_build_stats(pts, npts, hull, NULL, diag);
}

static pd_status hull_build(const pd_vec3 *pts, int npts, pd_cancel_flag *cancel, pd_hull **hull,
                            pd_hull_merge_stats *stats, pd_diag *diag);

pd_status pd_hull_build_stats(const pd_vec3 *pts, int npts, pd_hull **hull, pd_hull_merge_stats *stats,
                              pd_diag *diag)
{
    return hull_build(pts, npts, NULL, hull, stats, diag);
}

pd_status pd_hull_build_cancel(const pd_vec3 *pts, int npts, pd_cancel_flag *cancel, pd_hull **hull,
                               pd_diag *diag)
{
    return hull_build(pts, npts, cancel, hull, NULL, diag);
}

static pd_status hull_build(const pd_vec3 *pts, int npts, pd_cancel_flag *cancel, pd_hull **hull,
                            pd_hull_merge_stats *stats, pd_diag *diag)
{
    if (!hull || (!pts && npts > 0) || npts < 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_hull_build: NULL argument or negative count");
    int seed[4];
    double size = 0.0;
    pd_status st = classify(pts, npts, seed, &size, diag);
    if (st != PD_OK)
        return st;
    pd_trihull th = {0, NULL, NULL};
    st = pd_trihull_build(pts, npts, seed, cancel, &th, diag);
    if (st != PD_OK)
        return st;
    pd_hull *h = calloc(1, sizeof *h);
    if (!h) {
        pd_trihull_free(&th);
        return pd_fail(diag, PD_ERR_NOMEM, "convex hull: out of memory");
    }
    h->size = size;
    st = pd_hull_merge(pts, &th, h, stats, diag);
    pd_trihull_free(&th);
#ifdef PD_DEBUG
    if (st == PD_OK)
        st = pd_hull_check(h, pts, npts, diag);
#endif
    if (st != PD_OK) {
        pd_hull_free(h);
        return st;
    }
    *hull = h;
    return PD_OK;
}

void pd_hull_free(pd_hull *hull)
{
    if (!hull)
        return;
    free(hull->verts);
    free(hull->vert_source);
    free(hull->normal);
    free(hull->offset);
    free(hull->facet_start);
    free(hull->facet_vert);
    free(hull->facet_adj);
    free(hull);
}
