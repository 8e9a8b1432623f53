/* test_limits.c: parts at the edges of what the library supports: flat
 * shapes, parts far from the origin, the supported range of sizes, and the
 * refusals beyond them (docs/limits.md). */
#include <float.h>
#include <stdint.h>
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

/* A unit cube's corners and m points on each face (drawn from rng): on the
 * face planes exactly, wherever the coordinates are exact. */
static int cube_with_face_points(test_rng *rng, int m, pd_vec3 *p)
{
    int n = pts_box(1, 1, 1, p);
    for (int f = 0; f < 6; f++)
        for (int i = 0; i < m; i++) {
            double a = rng_range(rng, -0.5, 0.5), b = rng_range(rng, -0.5, 0.5);
            double c = (f & 1) ? 0.5 : -0.5;
            p[n++] = f < 2 ? v3(c, a, b) : f < 4 ? v3(a, c, b) : v3(a, b, c);
        }
    return n;
}

/* A 1 um cube with points on its faces, turned at random and placed 1e6 m
 * from the origin (1e12 times its size), as in issue 18: its coordinates are
 * rounded in steps of 1.2e-10 m, 1e-4 of its size, so its faces carry bumps
 * of that size, but its heights must not carry that much again: computed in
 * the file's frame they did (links "rising" by one step, exit 1). In the
 * part's frame the estimate answers, each face near 1/6 (the bumps move the
 * centre and the faces by ~1e-4 L: 1e-3 leaves a margin of 10; a face the
 * bumps split counts with its pieces), and warns once that the coordinates
 * are coarse. */
static void test_far_part(void)
{
    int bad = 0;
    for (int seed = 1; seed <= 20; seed++) {
        test_rng rng = {(uint64_t)seed};
        pd_vec3 p[8 + 6 * 5];
        int n = cube_with_face_points(&rng, 5, p);
        double R[3][3];
        rng_rotation(&rng, R);
        points_transform(p, n, CR(R), 1e-6, v3(1e6, 0.7e6, -0.3e6));
        pd_part *part = NULL;
        pd_diag d;
        pd_diag_init(&d);
        pd_status st = part_of_points(p, n, &part, &d);
        pd_static_result *r = NULL;
        if (st == PD_OK)
            st = pd_static_estimate(part, NULL, &r, &d);
        int ok = st == PD_OK && d.nwarnings == 1;
        double sum = 0.0, face[6] = {0, 0, 0, 0, 0, 0};
        for (int i = 0; ok && i < r->nposes; i++) {
            /* A face whose bumps split it rests on either piece: its
             * poses' normals lie within ~1e-4 rad of the face's. */
            int k = -1;
            for (int j = 0; j < 6; j++) {
                pd_vec3 e = v3(j / 2 == 0, j / 2 == 1, j / 2 == 2);
                e = rot_apply(CR(R), j & 1 ? e : v3_neg(e));
                if (v3_dist(r->poses[i].normal, e) < 1e-3)
                    k = j;
            }
            ok = k >= 0;
            if (ok)
                face[k] += r->poses[i].p_qs;
            sum += r->poses[i].p_qs;
        }
        for (int j = 0; ok && j < 6; j++)
            ok = fabs(face[j] - 1.0 / 6.0) <= 1e-3;
        if (!ok || fabs(sum - 1.0) > 1e-12) {
            printf("     far cube seed %d: %s, %d poses, sum %.17g\n", seed,
                   st == PD_OK ? "answered" : d.message, r ? r->nposes : 0, sum);
            bad++;
        }
        pd_static_result_free(r);
        pd_part_free(part);
    }
    CHECK_INT(bad, 0);
}

/* Moving a part by a multiple of the power of two at or above its size moves
 * its origin by exactly that and its points not at all in its own frame: the
 * results are the same bits (here the coordinates are multiples of 2^-30 and
 * the move 2^21 m, so every coordinate stays exact). */
static void test_placement_bits(void)
{
    test_rng rng = {7};
    pd_vec3 p[8 + 6 * 4], q[8 + 6 * 4];
    int n = cube_with_face_points(&rng, 4, p);
    for (int i = 0; i < n; i++) {
        p[i] = v3(ldexp(round(ldexp(p[i].x, 30)), -30), ldexp(round(ldexp(p[i].y, 30)), -30),
                  ldexp(round(ldexp(p[i].z, 30)), -30));
        q[i] = v3_add(p[i], v3(ldexp(1, 21), -ldexp(3, 20), ldexp(1, 19)));
    }
    pd_part *a = NULL, *b = NULL;
    pd_static_result *ra = NULL, *rb = NULL;
    CHECK_STATUS(part_of_points(p, n, &a, NULL), PD_OK);
    CHECK_STATUS(part_of_points(q, n, &b, NULL), PD_OK);
    if (a && b) {
        CHECK(v3_dist(b->origin, v3_add(a->origin, v3(ldexp(1, 21), -ldexp(3, 20), ldexp(1, 19)))) == 0);
        CHECK_STATUS(pd_static_estimate(a, NULL, &ra, NULL), PD_OK);
        CHECK_STATUS(pd_static_estimate(b, NULL, &rb, NULL), PD_OK);
    }
    if (ra && rb) {
        CHECK_INT(ra->nfacets, rb->nfacets);
        int same = ra->nfacets == rb->nfacets;
        for (int f = 0; same && f < ra->nfacets; f++)
            same = memcmp(&ra->facets[f], &rb->facets[f], sizeof ra->facets[f]) == 0;
        CHECK(same);
    }
    pd_static_result_free(ra);
    pd_static_result_free(rb);
    pd_part_free(a);
    pd_part_free(b);
}

void suite_limits(void)
{
    test_flat_pyramids();
    test_far_part();
    test_placement_bits();
}
