/* tangent.c: forward-mode derivatives of the QS and PQS probabilities
 * (tangent.h). Every area is differentiated in closed form:
 *  - a triangle's solid angle from Van Oosterom and Strackee's
 *    tan(omega / 2) = N / D, N = a . (b x c),
 *    D = |a||b||c| + (a.b)|c| + (a.c)|b| + (b.c)|a|, so that
 *    d omega = 2 (D dN - N dD) / (N^2 + D^2);
 *  - an arc's length atan2(|a x b|, a . b) likewise;
 *  - a facet's normal from its Newell vector (1/2) sum v_k x v_k+1, whose
 *    derivative is linear in the corners' motion. */
#include <stdlib.h>
#include "static/static_internal.h"
#include "static/tangent.h"
#include "base/vec3.h"

/* The derivative of D with respect to corner a (the others are the same
 * expression with the corners permuted): a^ (|b||c| + b.c) + b |c| + c |b|. */
static double den_d(pd_vec3 a, pd_vec3 b, pd_vec3 c, pd_vec3 da)
{
    double la = v3_norm(a), lb = v3_norm(b), lc = v3_norm(c);
    pd_vec3 g = v3_add(v3_scale(a, (lb * lc + v3_dot(b, c)) / la),
                       v3_add(v3_scale(b, lc), v3_scale(c, lb)));
    return v3_dot(g, da);
}

double pd_solid_angle_triangle_d(pd_vec3 a, pd_vec3 b, pd_vec3 c, pd_vec3 da, pd_vec3 db,
                                 pd_vec3 dc, double *d)
{
    double num = v3_dot(a, v3_cross(v3_sub(b, a), v3_sub(c, a)));
    double la = v3_norm(a), lb = v3_norm(b), lc = v3_norm(c);
    double den = la * lb * lc + v3_dot(a, b) * lc + v3_dot(a, c) * lb + v3_dot(b, c) * la;
    double dnum = v3_dot(da, v3_cross(b, c)) + v3_dot(db, v3_cross(c, a)) +
                  v3_dot(dc, v3_cross(a, b));
    double dden = den_d(a, b, c, da) + den_d(b, c, a, db) + den_d(c, a, b, dc);
    *d = 2.0 * (den * dnum - num * dden) / (num * num + den * den);
    return 2.0 * atan2(num, den);
}

/* The angle between a and b and its derivative. */
static double angle_d(pd_vec3 a, pd_vec3 b, pd_vec3 da, pd_vec3 db, double *d)
{
    pd_vec3 x = v3_cross(a, b);
    double s = v3_norm(x), c = v3_dot(a, b);
    double ds = s > 0.0 ? v3_dot(x, v3_add(v3_cross(da, b), v3_cross(a, db))) / s : 0.0;
    double dc = v3_dot(da, b) + v3_dot(a, db);
    *d = (c * ds - s * dc) / (s * s + c * c);
    return atan2(s, c);
}

/* Facet f's solid angle from com, fanned from its first corner (the value
 * is pd_solid_angle_facet's; only the derivative is wanted here). */
static double facet_omega_d(const pd_hull *h, pd_vec3 com, const pd_vec3 *dv, pd_vec3 dcom, int f)
{
    const int *loop = h->facet_vert + h->facet_start[f];
    int k = h->facet_start[f + 1] - h->facet_start[f];
    pd_vec3 a = v3_sub(h->verts[loop[0]], com), da = v3_sub(dv[loop[0]], dcom);
    double sum = 0.0;
    for (int i = 1; i + 1 < k; i++) {
        double d;
        pd_solid_angle_triangle_d(a, v3_sub(h->verts[loop[i]], com),
                                  v3_sub(h->verts[loop[i + 1]], com), da,
                                  v3_sub(dv[loop[i]], dcom), v3_sub(dv[loop[i + 1]], dcom), &d);
        sum += d;
    }
    return sum;
}

/* The motion of facet f's foot of the centre of mass, relative to com:
 * foot - com = n h, h = n . (v0 - com), n the Newell normal's direction. */
static pd_vec3 foot_d(const pd_hull *h, pd_vec3 com, const pd_vec3 *dv, pd_vec3 dcom, int f)
{
    const int *loop = h->facet_vert + h->facet_start[f];
    int k = h->facet_start[f + 1] - h->facet_start[f];
    pd_vec3 N = v3(0, 0, 0), dN = v3(0, 0, 0);
    for (int i = 0; i < k; i++) {
        pd_vec3 p = h->verts[loop[i]], q = h->verts[loop[(i + 1) % k]];
        N = v3_add(N, v3_cross(p, q));
        dN = v3_add(dN, v3_add(v3_cross(dv[loop[i]], q), v3_cross(p, dv[loop[(i + 1) % k]])));
    }
    pd_vec3 n = h->normal[f];
    double len = v3_norm(N);
    pd_vec3 dn = v3_scale(v3_sub(dN, v3_scale(n, v3_dot(n, dN))), 1.0 / len);
    pd_vec3 r0 = v3_sub(h->verts[loop[0]], com);
    double hh = v3_dot(n, r0);
    double dh = v3_dot(dn, r0) + v3_dot(n, v3_sub(dv[loop[0]], dcom));
    return v3_add(v3_scale(dn, hh), v3_scale(n, dh));
}

pd_status pd_static_tangent(const pd_hull *h, pd_vec3 com, const pd_static_options *opt,
                            const pd_static_result *res, const pd_vec3 *dv, pd_vec3 dcom,
                            double *dp_raw, double *dp_qs, double *dp_pqs)
{
    if (opt->band == PD_PQS_BAND_EXACT && opt->epsilon > 0.0)
        return PD_ERR_USAGE;
    int n = h->nfacets;
    double *draw = malloc(sizeof *draw * (size_t)n * 3);
    if (!draw)
        return PD_ERR_NOMEM;
    double *pert = draw + n, *dpert = draw + 2 * n;
    const pd_facet_result *fr = res->facets;
    for (int f = 0; f < n; f++) {
        draw[f] = facet_omega_d(h, com, dv, dcom, f) / (4.0 * M_PI);
        pert[f] = fr[f].p_raw;
        dpert[f] = draw[f];
    }
    /* The PQS bands, decided as pqs.c decides them. */
    for (int i = 0; i < n && opt->epsilon > 0.0; i++) {
        if (!fr[i].stable)
            continue;
        int base = h->facet_start[i], k = h->facet_start[i + 1] - base;
        pd_vec3 foot = v3_scale(h->normal[i], fr[i].height);
        pd_vec3 dfoot = foot_d(h, com, dv, dcom, i);
        for (int e = 0; e < k; e++) {
            int j = h->facet_adj[base + e];
            if (!pd_pqs_moves(opt, res, i, j))
                continue;
            int ia = h->facet_vert[base + e], ib = h->facet_vert[base + (e + 1) % k];
            pd_vec3 a = v3_sub(h->verts[ia], com), b = v3_sub(h->verts[ib], com);
            pd_vec3 da = v3_sub(dv[ia], dcom), db = v3_sub(dv[ib], dcom);
            double tri = pd_solid_angle_from_nearest(foot, a, b), dtri, darc;
            pd_solid_angle_triangle_d(foot, a, b, dfoot, da, db, &dtri);
            double area = angle_d(a, b, da, db, &darc) * opt->epsilon;
            double dp = fmin(area, tri) / (4.0 * M_PI);
            double ddp = (area <= tri ? darc * opt->epsilon : dtri) / (4.0 * M_PI);
            pert[i] -= dp;
            pert[j] += dp;
            dpert[i] -= ddp;
            dpert[j] += ddp;
        }
    }
    for (int f = 0; f < n; f++) {
        if (dp_raw)
            dp_raw[f] = draw[f];
        if (dp_qs)
            dp_qs[f] = 0.0;
        if (dp_pqs)
            dp_pqs[f] = 0.0;
    }
    for (int f = 0; f < n; f++) {
        int r = fr[f].rest;
        if (dp_qs)
            dp_qs[r] += draw[f];
        /* A facet whose bands took all of it stays at 0 (pqs.c's clamp). */
        if (dp_pqs && pert[f] > 0.0)
            dp_pqs[r] += dpert[f];
    }
    free(draw);
    return PD_OK;
}
