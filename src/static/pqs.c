/* pqs.c: the perturbed quasi-static bands (paper, section 4).
 *
 * For a stable facet F_i and its edge e shared with F_j, let T be the triangle
 * of e and the foot of the centre of mass on F_i. Seen from the centre of mass,
 * T is a spherical triangle (A, B, N): A, B the directions of e's ends, N the
 * facet normal. Gravity directions within epsilon of the arc AB are those a
 * tilt of epsilon can carry across e. The paper approximates that band by
 * |AB| * epsilon, which can exceed T itself (a short, high triangle), so it is
 * clipped to T's solid angle; PD_PQS_BAND_EXACT integrates the band's true
 * area instead. The band moves from F_i to F_j when F_j is unstable or F_i is
 * strictly less probable; every decision is taken on the unperturbed values
 * and all moves are applied together, so the order of edges cannot matter. */
#include <math.h>
#include "base/fail.h"
#include "base/gsl_adapter.h"
#include "posedrop/tolerances.h"
#include "static/static_tol.h"
#include "static/static_internal.h"
#include "base/vec3.h"

/* --- exact band area -------------------------------------------------------- */

/* Latitude phi is measured from the great circle AB towards N (pole m),
 * longitude from A. At each latitude below N's, the triangle is the longitude
 * interval between its sides AN and BN; the band's area is the integral of
 * that interval's width times cos(phi). */
typedef struct band {
    pd_vec3 m, e1, e2; /* pole of AB on N's side; A; m x A */
    pd_vec3 A, UA;     /* side A -> N: x(t) = A cos t + UA sin t */
    pd_vec3 B, UB;
    double sa, sb;     /* UA . m, UB . m: sin(latitude) grows as sin(t) times these */
} band;

static double longitude(const band *b, pd_vec3 x)
{
    return atan2(v3_dot(x, b->e2), v3_dot(x, b->e1));
}

/* The point of side P -> N (tangent U, slope s) at latitude phi. */
static pd_vec3 side_at(pd_vec3 P, pd_vec3 U, double s, double sin_phi)
{
    double st = fmin(1.0, sin_phi / s), ct = sqrt(fmax(0.0, 1.0 - st * st));
    return v3_add(v3_scale(P, ct), v3_scale(U, st));
}

static double band_width(double phi, void *user)
{
    const band *b = user;
    double sp = sin(phi);
    double w = longitude(b, side_at(b->B, b->UB, b->sb, sp)) -
               longitude(b, side_at(b->A, b->UA, b->sa, sp));
    return fabs(w) * cos(phi);
}

pd_status pd_band_area_exact(pd_vec3 A, pd_vec3 B, pd_vec3 N, double eps, double *area)
{
    band b;
    b.m = v3_unit(v3_cross(A, B));
    if (v3_dot(b.m, N) < 0.0)
        b.m = v3_neg(b.m);
    double phi_n = asin(fmin(1.0, v3_dot(N, b.m)));
    if (eps >= phi_n) {
        /* The band covers the whole triangle. */
        *area = fabs(pd_solid_angle_triangle(A, B, N));
        return PD_OK;
    }
    b.e1 = A;
    b.e2 = v3_cross(b.m, A);
    b.A = A;
    b.B = B;
    b.UA = v3_unit(v3_sub(N, v3_scale(A, v3_dot(N, A))));
    b.UB = v3_unit(v3_sub(N, v3_scale(B, v3_dot(N, B))));
    b.sa = v3_dot(b.UA, b.m);
    b.sb = v3_dot(b.UB, b.m);
    return pd_quad_integrate(band_width, &b, 0.0, eps, PD_TOL_BAND_QUAD_REL, area);
}

/* --- transfers -------------------------------------------------------------- */

/* 1 if q is larger than p beyond a relative tie. */
static int strictly_greater(double q, double p)
{
    return q - p > PD_TOL_PROB_TIE_REL * fmax(fabs(p), fabs(q));
}

int pd_pqs_moves(const pd_static_options *opt, const pd_static_result *res, int i, int j)
{
    const pd_facet_result *fr = res->facets;
    if (!fr[j].stable)
        return 1;
    int qs = opt->compare == PD_PQS_COMPARE_QS;
    return strictly_greater(qs ? fr[j].p_qs : fr[j].p_raw, qs ? fr[i].p_qs : fr[i].p_raw);
}

pd_status pd_pqs_perturb(const pd_hull *hull, pd_vec3 com, const facet_geom *geom,
                         const pd_static_options *opt, const pd_static_result *res,
                         double *pert, pd_diag *diag)
{
    const pd_facet_result *fr = res->facets;
    for (int f = 0; f < hull->nfacets; f++)
        pert[f] = fr[f].p_raw;
    if (opt->epsilon <= 0.0)
        return PD_OK;
    for (int i = 0; i < hull->nfacets; i++) {
        if (!fr[i].stable)
            continue;
        int base = hull->facet_start[i], k = hull->facet_start[i + 1] - base;
        pd_vec3 foot = v3_sub(geom[i].foot, com);
        for (int e = 0; e < k; e++) {
            int j = hull->facet_adj[base + e];
            if (!pd_pqs_moves(opt, res, i, j))
                continue;
            pd_vec3 a = v3_sub(hull->verts[hull->facet_vert[base + e]], com);
            pd_vec3 b = v3_sub(hull->verts[hull->facet_vert[base + (e + 1) % k]], com);
            double tri = pd_solid_angle_from_nearest(foot, a, b), area;
            if (opt->band == PD_PQS_BAND_EXACT) {
                pd_status st = pd_band_area_exact(v3_unit(a), v3_unit(b), hull->normal[i],
                                                  opt->epsilon, &area);
                if (st != PD_OK)
                    return pd_fail(diag, st, "PQS band of facet %d, edge %d: quadrature failed",
                                   i + 1, e + 1);
            } else {
                area = v3_angle(a, b) * opt->epsilon;
            }
            double dp = fmin(area, tri) / (4.0 * M_PI);
            pert[i] -= dp;
            pert[j] += dp;
        }
    }
    /* A facet whose every band is clipped gives away its whole solid angle,
     * summed over its triangles T, which matches p_raw (summed over another
     * fan) only to round-off: what is left may be -1e-20, never a real
     * negative probability. */
    for (int f = 0; f < hull->nfacets; f++)
        if (pert[f] < 0.0)
            pert[f] = 0.0;
    return PD_OK;
}
