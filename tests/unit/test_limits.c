/* test_limits.c: parts at the edges of what the library supports: flat
 * shapes, parts far from the origin, the supported range of sizes, and the
 * refusals beyond them (docs/limits.md). */
#include <float.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

/* 1 if following next[] from every facet reaches its rest[], a stable facet,
 * in at most nfacets steps with the height falling at every unstable link
 * (beyond PD_TOL_HEIGHT_REL L, the graph's own check). */
static int graph_descends(const pd_static_result *r, double L)
{
    for (int f = 0; f < r->nfacets; f++) {
        int g = f, steps = 0;
        while (!r->facets[g].stable) {
            int n = r->facets[g].next;
            if (n < 0 || n >= r->nfacets || ++steps > r->nfacets ||
                r->facets[n].height > r->facets[g].height + PD_TOL_HEIGHT_REL * L)
                return 0;
            g = n;
        }
        if (r->facets[f].rest != g)
            return 0;
    }
    return 1;
}

/* A regular pyramid of circumradius 1 and height h: the centre of mass is on
 * the axis at h/4, so its foot on every side facet lies at the apex, inside
 * the facet by ~h^2 (within the knife band when h <~ 4e-6): every side is
 * stable, exactly, and keeps its solid angle. Swept over side counts 3..64
 * and h from 1e-7 to 1e-3 in quarter decades, under both topple rules: each
 * part is refused with a user error (flat below PD_TOL_PLANE_REL, or its
 * centre of mass within PD_TOL_COM_INSIDE_REL of the base) or answered. */
static void test_flat_pyramids(void)
{
    int answered = 0, refused = 0, bad = 0;
    for (int n = 3; n <= 64; n++)
        for (int e = 0; e <= 16; e++) {
            double h = pow(10.0, -7.0 + 0.25 * e);
            pd_vec3 p[65];
            int np = pts_flat_pyramid(n, h, p);
            pd_part *part = NULL;
            pd_diag d;
            pd_diag_init(&d);
            pd_status st = part_of_points(p, np, &part, &d);
            /* The bounding-box diagonal of the ring (h adds below 1e-6). */
            double L = part ? part->size : 0.0;
            if (st != PD_OK) {
                refused++;
                pd_vec3 lo = p[0], hi = p[0];
                for (int i = 1; i < np; i++) {
                    lo = v3(fmin(lo.x, p[i].x), fmin(lo.y, p[i].y), fmin(lo.z, p[i].z));
                    hi = v3(fmax(hi.x, p[i].x), fmax(hi.y, p[i].y), fmax(hi.z, p[i].z));
                }
                L = v3_dist(lo, hi);
                /* Refused only as flat, or for the centre of mass on the
                 * base, and only where those tolerances say (1% for the
                 * centroid's round-off and the ring's bounding box). */
                int why = (st == PD_ERR_COPLANAR && h <= 1.01 * PD_TOL_PLANE_REL * L) ||
                          (st == PD_ERR_COM_OUTSIDE && h / 4 <= 1.01 * PD_TOL_COM_INSIDE_REL * L);
                if (!why) {
                    printf("     pyramid n %d h %.3g refused: %s\n", n, h, d.message);
                    bad++;
                }
                continue;
            }
            if (h / 4 < 0.99 * PD_TOL_COM_INSIDE_REL * L) {
                printf("     pyramid n %d h %.3g accepted within the tolerance\n", n, h);
                bad++;
            }
            for (int rule = 0; rule < 2; rule++) {
                pd_static_options o;
                pd_static_options_default(&o);
                o.topple = rule ? PD_TOPPLE_EDGE : PD_TOPPLE_DESCENT;
                pd_static_result *r = NULL;
                st = pd_static_estimate(part, &o, &r, &d);
                if (st != PD_OK) {
                    printf("     pyramid n %d h %.3g rule %d: %s\n", n, h, rule, d.message);
                    bad++;
                    continue;
                }
                answered++;
                double qs = 0, pqs = 0, side = -1, base = -1;
                int ok = graph_descends(r, L);
                for (int i = 0; i < r->nposes; i++) {
                    const pd_pose *ps = &r->poses[i];
                    qs += ps->p_qs;
                    pqs += ps->p_pqs;
                    if (ps->normal.z < -0.5)
                        base = ps->p_qs;
                    else if (side < 0)
                        side = ps->p_qs;
                    /* Unless the hull merged some (their planes within
                     * PD_TOL_PLANE_REL L of one another), the sides are
                     * images of each other under rotations about the axis:
                     * equal to the round-off of their solid angles (below,
                     * ~1e-10 relative at the flattest; 1e-9 leaves room). */
                    else if (r->nposes == n + 1 && fabs(ps->p_qs - side) > 1e-9 * side)
                        ok = 0;
                }
                /* Seen from h/4 on the axis, the base subtends at least the
                 * disc of its inradius a >= 1/2: p >= (1 - (h/4)/a) / 2, and
                 * at most a half-space, 1/2. The sums are 1 to round-off, but
                 * on a part this flat the corners lie within an angle ~h/L of
                 * the horizon seen from the centre of mass, and the solid
                 * angles there are conditioned like L/h: the bound is
                 * 1e-12 + DBL_EPSILON L/h (measured up to 0.06 of the
                 * second term). */
                double sum_tol = 1e-12 + DBL_EPSILON * L / h;
                ok = ok && fabs(qs - 1) <= sum_tol && fabs(pqs - 1) <= sum_tol && base <= 0.5 &&
                     base >= 0.5 * (1 - h / 2);
                if (!ok) {
                    printf("     pyramid n %d h %.3g rule %d: %d poses, sums %.17g %.17g, base %.17g\n",
                           n, h, rule, r->nposes, qs, pqs, base);
                    bad++;
                }
                pd_static_result_free(r);
            }
            pd_part_free(part);
        }
    CHECK_INT(bad, 0);
    /* Both outcomes occur: the sweep reaches into the refusals and well
     * above them (h = 2e-6 and up, 12 of 17 steps, are answered). */
    CHECK(refused > 0);
    CHECK(answered >= 2 * 62 * 12);
}

void suite_limits(void)
{
    test_flat_pyramids();
}
