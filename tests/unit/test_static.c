/* test_static.c: the QS and PQS estimators against closed forms, invariances
 * and hard cases. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "static/static_internal.h"
#include "suites.h"
#include "base/vec3.h"

/* --- helpers ----------------------------------------------------------------- */

static pd_static_result *estimate(const pd_part *part, const pd_static_options *o)
{
    pd_static_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_static_estimate(part, o, &r, &d);
    if (st != PD_OK)
        printf("     estimate: %s (%s)\n", pd_status_str(st), d.message);
    return r;
}

/* Solid angle of an a x b rectangle seen from distance d on its axis, in the
 * atan form (the asin form is ill-conditioned near a hemisphere). */
static double rect_omega(double a, double b, double d)
{
    return 4.0 * atan(a * b / (2 * d * sqrt(a * a + b * b + 4 * d * d)));
}

/* Solid angle of a right triangle seen from height d above its vertex P,
 * whose leg from P meets the opposite leg (length t) at a right angle at
 * distance p: atan(t/p) - atan(t d / (p sqrt(S))), S = p^2 + t^2 + d^2,
 * combined into one atan so that nothing cancels for slivers. */
static double right_triangle_omega(double p, double t, double d)
{
    double sq = sqrt(p * p + t * t + d * d);
    return atan(t * p * (p * p + t * t) / ((sq + d) * (p * p * sq + t * t * d)));
}

/* The paper's route, eqs. (1)-(3) with the errata applied: arcs by the law of
 * cosines, angles by the spherical law of cosines, then the excess. */
static double paper_omega(pd_vec3 v0, pd_vec3 v1, pd_vec3 v2)
{
    pd_vec3 v[3] = {v0, v1, v2};
    double delta[3], beta[3];
    for (int i = 0; i < 3; i++) {
        pd_vec3 p = v[(i + 1) % 3], q = v[(i + 2) % 3];
        double dp = v3_norm(p), dq = v3_norm(q), dpq = v3_dist(p, q);
        delta[i] = acos((dp * dp + dq * dq - dpq * dpq) / (2 * dp * dq));
    }
    for (int i = 0; i < 3; i++) {
        double d0 = delta[(i + 1) % 3], d1 = delta[(i + 2) % 3];
        beta[i] = acos((cos(delta[i]) - cos(d0) * cos(d1)) / (sin(d0) * sin(d1)));
    }
    return beta[0] + beta[1] + beta[2] - M_PI;
}

static double sum_qs(const pd_static_result *r, int pqs)
{
    double s = 0.0;
    for (int i = 0; i < r->nposes; i++)
        s += pqs ? r->poses[i].p_pqs : r->poses[i].p_qs;
    return s;
}

/* The pose whose normal is n (within 1e-9), or NULL. */
static const pd_pose *pose_with_normal(const pd_static_result *r, pd_vec3 n)
{
    for (int i = 0; i < r->nposes; i++)
        if (v3_dist(r->poses[i].normal, n) < 1e-9)
            return &r->poses[i];
    return NULL;
}

/* --- solid angles ------------------------------------------------------------ */

static void test_solid_angle(void)
{
    /* The octant triangle subtends exactly pi / 2; reversing the loop negates. */
    pd_vec3 x = v3(1, 0, 0), y = v3(0, 1, 0), z = v3(0, 0, 1);
    CHECK_REL(pd_solid_angle_triangle(x, y, z), M_PI / 2, 4e-16, "round-off, closed form");
    CHECK_REL(pd_solid_angle_triangle(x, z, y), -M_PI / 2, 4e-16, "round-off, closed form");

    /* Rectangles on their axis, from large to tiny and thin; the rectangle is
     * two congruent triangles (180-degree symmetry about the axis). */
    const double dims[][3] = {{1, 1, 1}, {2, 0.5, 0.1}, {1e-2, 1e-2, 1}, {1e-3, 1e-3, 1},
                              {1e-6, 1e-6, 1}, {1, 1e-9, 1}, {1e-8, 3e-9, 1e3}};
    for (size_t i = 0; i < sizeof dims / sizeof dims[0]; i++) {
        double a = dims[i][0], b = dims[i][1], d = dims[i][2];
        pd_vec3 p0 = v3(-a / 2, -b / 2, d), p1 = v3(a / 2, -b / 2, d), p2 = v3(a / 2, b / 2, d),
                p3 = v3(-a / 2, b / 2, d);
        double got = pd_solid_angle_triangle(p0, p1, p2) + pd_solid_angle_triangle(p0, p2, p3);
        CHECK_REL(got, rect_omega(a, b, d), 1e-13, "round-off against the closed form");
    }

    /* Where the paper's law-of-cosines route fails (docs/readings.md, "Solid
     * angles"): a facet of 1e-3 at distance 1 loses most digits, a sliver
     * gives NaN or garbage, while the atan2 form stays at round-off. */
    {
        double a = 1e-3, d = 1.0, exact = rect_omega(a, a, d) / 2;
        pd_vec3 p0 = v3(-a / 2, -a / 2, d), p1 = v3(a / 2, -a / 2, d), p2 = v3(a / 2, a / 2, d);
        double paper = paper_omega(p0, p1, p2), ours = pd_solid_angle_triangle(p0, p1, p2);
        CHECK(fabs(paper - exact) > 1e-6 * exact);
        CHECK_REL(ours, exact, 1e-13, "round-off");
        /* Half of a 1 x 1e-9 rectangle on the axis at distance 1. */
        double w = 1e-9, sliver = rect_omega(1, w, 1) / 2;
        pd_vec3 s0 = v3(-0.5, -w / 2, 1), s1 = v3(0.5, -w / 2, 1), s2 = v3(0.5, w / 2, 1);
        double paper_sliver = paper_omega(s0, s1, s2);
        CHECK(!(fabs(paper_sliver - sliver) < 1e-3 * sliver));
        CHECK_REL(pd_solid_angle_triangle(s0, s1, s2), sliver, 1e-13, "round-off");
    }

    /* Fanned from the nearest point, a large facet seen from very close keeps
     * full precision where a corner fan loses ~1e-12 (the regime of
     * docs/readings.md, "Solid angles", turned around: the tile below is
     * 1 x 0.8 seen from 5e-5). */
    {
        double a = 1, b = 0.8, d = 5e-5, exact = rect_omega(a, b, d);
        pd_vec3 q = v3(0, 0, d); /* the foot: nearest point of the facet */
        pd_vec3 c[4] = {v3(-a / 2, -b / 2, d), v3(a / 2, -b / 2, d), v3(a / 2, b / 2, d),
                        v3(-a / 2, b / 2, d)};
        double fan = 0;
        for (int i = 0; i < 4; i++)
            fan += pd_solid_angle_from_nearest(q, c[i], c[(i + 1) % 4]);
        CHECK_REL(fan, exact, 4e-16 * 8, "round-off of 8 triangles");
        /* Foot near an edge (obtuse angles at q are split). */
        pd_vec3 e0 = v3(-1, 1e-7, d), e1 = v3(1, 1e-7, d), e2 = v3(1, 2, d), e3 = v3(-1, 2, d);
        double near_edge = pd_solid_angle_from_nearest(q, e0, e1) +
                           pd_solid_angle_from_nearest(q, e1, e2) +
                           pd_solid_angle_from_nearest(q, e2, e3) +
                           pd_solid_angle_from_nearest(q, e3, e0);
        /* Closed form: the 2 x 2 rectangle [-1,1] x [0,2] seen from above
         * (0, 0) is two corner rectangles, minus the 2 x 1e-7 strip. */
        double corner = 2 * atan(1 * 2 / (d * sqrt(1 + 4 + d * d)));
        double strip = 2 * atan(1 * 1e-7 / (d * sqrt(1 + 1e-14 + d * d)));
        CHECK_REL(near_edge, corner - strip, 1e-14, "closed form, round-off");
    }
}

/* --- closed forms -------------------------------------------------------------- */

/* Expected PQS of a box (every face stable): the band of each edge moves to
 * the face across when that face is strictly more probable. */
static void box_expected(double ax, double ay, double az, double eps, double qs[6],
                         double pqs[6], pd_vec3 normal[6])
{
    double dim[3] = {ax, ay, az};
    for (int f = 0; f < 6; f++) {
        int axis = f / 2, u = (axis + 1) % 3, w = (axis + 2) % 3;
        double d = dim[axis] / 2;
        qs[f] = rect_omega(dim[u], dim[w], d) / (4 * M_PI);
        double nn[3] = {0, 0, 0};
        nn[axis] = f % 2 ? 1 : -1;
        normal[f] = v3(nn[0], nn[1], nn[2]);
    }
    for (int f = 0; f < 6; f++)
        pqs[f] = qs[f];
    for (int f = 0; f < 6; f++) {
        int axis = f / 2;
        double d = dim[axis] / 2;
        for (int side = 0; side < 2; side++) {
            /* Edges parallel to axis u lie against the faces normal to w. */
            int u = (axis + 1 + side) % 3, w = (axis + 2 - side) % 3;
            double hu = dim[u] / 2, hw = dim[w] / 2;
            for (int sgn = 0; sgn < 2; sgn++) {
                int g = 2 * w + sgn;
                if (!(qs[g] - qs[f] > PD_TOL_PROB_TIE_REL * qs[g]))
                    continue;
                /* The edge of length 2 hu at distance hw from the foot. */
                double arc = 2 * atan(hu / sqrt(hw * hw + d * d));
                double tri = 2 * right_triangle_omega(hw, hu, d);
                double dp = fmin(arc * eps, tri) / (4 * M_PI);
                pqs[f] -= dp;
                pqs[g] += dp;
            }
        }
    }
}

static void test_boxes(void)
{
    const double dims[][3] = {{1, 1, 1}, {1, 2, 3}, {3, 1, 0.5}, {1, 0.8, 1e-4}, {0.01, 0.02, 0.2}};
    const double eps[] = {20 * M_PI / 180, 2 * M_PI / 180, 60 * M_PI / 180};
    for (size_t i = 0; i < sizeof dims / sizeof dims[0]; i++) {
        pd_vec3 c = v3(0, 0, 0);
        pd_part *part = part_of(mesh_box(dims[i][0], dims[i][1], dims[i][2]), &c, NULL);
        CHECK(part != NULL);
        if (!part)
            continue;
        for (size_t e = 0; e < sizeof eps / sizeof eps[0]; e++) {
            pd_static_options o;
            pd_static_options_default(&o);
            o.epsilon = eps[e];
            pd_static_result *r = estimate(part, &o);
            CHECK(r != NULL);
            if (!r)
                continue;
            double qs[6], pqs[6];
            pd_vec3 nrm[6];
            box_expected(dims[i][0], dims[i][1], dims[i][2], eps[e], qs, pqs, nrm);
            CHECK_INT(r->nposes, 6);
            for (int f = 0; f < 6; f++) {
                const pd_pose *p = pose_with_normal(r, nrm[f]);
                CHECK(p != NULL);
                if (!p)
                    continue;
                CHECK_REL(p->p_qs, qs[f], 1e-12, "closed form, round-off");
                CHECK_NEAR(p->p_pqs, pqs[f], 1e-13, "closed form, round-off");
                int axis = f / 2;
                CHECK_REL(p->height, dims[i][axis] / 2, 1e-12, "half the box's edge");
                CHECK_REL(p->area, dims[i][(axis + 1) % 3] * dims[i][(axis + 2) % 3], 1e-12,
                          "face area");
            }
            CHECK_NEAR(sum_qs(r, 0), 1.0, 1e-12, "probabilities sum to 1, round-off");
            CHECK_NEAR(sum_qs(r, 1), 1.0, 1e-12, "probabilities sum to 1, round-off");
            pd_static_result_free(r);
        }
        pd_part_free(part);
    }
}

static void test_prisms(void)
{
    /* Regular n-gon prisms, centre of mass at the centre: every side is an
     * s x h rectangle at the apothem's distance, the caps share the rest. */
    const int ns[] = {3, 5, 6, 8, 17, 32};
    const double ratios[] = {0.2, 1.0, 3.0};
    for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++)
        for (size_t j = 0; j < sizeof ratios / sizeof ratios[0]; j++) {
            int n = ns[i];
            double r = 1.0, h = ratios[j] * 2 * r;
            double apo = r * cos(M_PI / n), s = 2 * r * sin(M_PI / n);
            double side = rect_omega(s, h, apo) / (4 * M_PI), cap = (1.0 - n * side) / 2;
            pd_part *part = part_of(mesh_prism(n, r, h), NULL, NULL);
            CHECK(part != NULL);
            if (!part)
                continue;
            pd_static_result *res = estimate(part, NULL);
            CHECK(res != NULL);
            if (res) {
                CHECK_INT(res->nposes, n + 2);
                const pd_pose *top = pose_with_normal(res, v3(0, 0, 1));
                CHECK(top != NULL);
                if (top)
                    CHECK_REL(top->p_qs, cap, 1e-12, "closed form, round-off");
                for (int k = 0; k < res->nposes; k++)
                    if (fabs(res->poses[k].normal.z) < 0.5)
                        CHECK_REL(res->poses[k].p_qs, side, 1e-12, "closed form, round-off");
                CHECK_NEAR(sum_qs(res, 1), 1.0, 1e-12, "probabilities sum to 1, round-off");
                pd_static_result_free(res);
            }
            pd_part_free(part);
        }
}

/* A 32-gon prism whose coordinates are rounded to 7 significant digits, as
 * a CAD export would print them: its sides must still tie in PQS. */
static void test_printed_symmetry(void)
{
    pd_vec3 p[64];
    int n = pts_prism(32, 0.0115, 0.014, p);
    for (int i = 0; i < n; i++) {
        char buf[3][32];
        snprintf(buf[0], sizeof buf[0], "%.7g", p[i].x);
        snprintf(buf[1], sizeof buf[1], "%.7g", p[i].y);
        snprintf(buf[2], sizeof buf[2], "%.7g", p[i].z);
        p[i] = v3(strtod(buf[0], NULL), strtod(buf[1], NULL), strtod(buf[2], NULL));
    }
    pd_part *part = part_of(convex_mesh(p, n), NULL, NULL);
    pd_static_result *r = part ? estimate(part, NULL) : NULL;
    CHECK(r != NULL);
    if (r) {
        double lo = 1, hi = 0;
        for (int i = 0; i < r->nposes; i++)
            if (fabs(r->poses[i].normal.z) < 0.5) {
                lo = fmin(lo, r->poses[i].p_pqs);
                hi = fmax(hi, r->poses[i].p_pqs);
            }
        CHECK_NEAR(hi - lo, 0.0, 1e-8, "7-digit coordinates move solid angles by ~1e-7 relative");
    }
    pd_static_result_free(r);
    pd_part_free(part);
}

static void test_platonic(void)
{
    pd_vec3 p[64];
    int (*solids[])(pd_vec3 *) = {pts_tetrahedron, pts_cube, pts_octahedron, pts_dodecahedron,
                                  pts_icosahedron};
    const int faces[] = {4, 6, 8, 12, 20};
    for (int s = 0; s < 5; s++) {
        int n = solids[s](p);
        pd_part *part = part_of(convex_mesh(p, n), NULL, NULL);
        CHECK(part != NULL);
        if (!part)
            continue;
        pd_static_result *r = estimate(part, NULL);
        CHECK(r != NULL);
        if (r) {
            CHECK_INT(r->nposes, faces[s]);
            for (int i = 0; i < r->nposes; i++) {
                CHECK_REL(r->poses[i].p_qs, 1.0 / faces[s], 1e-12, "symmetry, round-off");
                CHECK_REL(r->poses[i].p_pqs, 1.0 / faces[s], 1e-12, "symmetry: ties never transfer");
            }
            pd_static_result_free(r);
        }
        pd_part_free(part);
    }
}

/* pts_parallelogram_prism's mesh: its centroid (1, 0.5, 0.5) projects
 * exactly onto the edge x = 1 of the bottom face and of the top face. */
static pd_mesh *parallelogram_prism(void)
{
    pd_vec3 p[8];
    return convex_mesh(p, pts_parallelogram_prism(p));
}

static void test_knife_edge(void)
{
    pd_diag d;
    pd_diag_init(&d);
    pd_part *part = part_of(parallelogram_prism(), NULL, &d);
    CHECK(part != NULL);
    if (!part)
        return;
    CHECK_NEAR(part->com.x, 1.0, 1e-15, "centroid, round-off");
    pd_static_result *r = NULL;
    CHECK_STATUS(pd_static_estimate(part, NULL, &r, &d), PD_OK);
    double L = part->size;
    if (r) {
        CHECK_INT(r->nknife, 2);
        CHECK(d.nwarnings >= 2);
        CHECK(pose_with_normal(r, v3(0, 0, -1)) == NULL); /* on the edge: unstable */
        CHECK_NEAR(sum_qs(r, 0), 1.0, 1e-12, "round-off");
    }
    pd_static_result_free(r);

    /* 1e-9 L to either side of the edge: stable inside, unstable outside,
     * and the bottom's probability is continuous across the knife. */
    double raw_bottom = -1;
    for (int side = -1; side <= 1; side += 2) {
        pd_vec3 c = v3(1.0 - side * 1e-9 * L, 0.5, 0.5);
        pd_part *q = part_of(parallelogram_prism(), &c, NULL);
        CHECK(q != NULL);
        if (!q)
            continue;
        pd_static_result *rq = estimate(q, NULL);
        CHECK(rq != NULL);
        if (rq) {
            const pd_pose *bottom = pose_with_normal(rq, v3(0, 0, -1));
            CHECK_INT(rq->nknife, 0);
            CHECK((bottom != NULL) == (side > 0));
            for (int f = 0; f < rq->nfacets; f++)
                if (v3_dist(q->hull->normal[f], v3(0, 0, -1)) < 1e-9)
                    raw_bottom = rq->facets[f].p_raw;
            if (bottom)
                CHECK_NEAR(bottom->p_qs, raw_bottom, 1e-8, "nothing else topples onto it");
            pd_static_result_free(rq);
        }
        pd_part_free(q);
    }
    pd_part_free(part);
}

/* --- invariance and sums -------------------------------------------------------- */

/* A random convex part from n points on an ellipsoid, centre of mass off
 * centre (given), as a closed mesh. */
static pd_mesh *random_convex(test_rng *rng, int n)
{
    pd_vec3 p[64];
    for (int i = 0; i < n; i++) {
        pd_vec3 u = rng_unit_vector(rng);
        p[i] = v3(u.x, 0.7 * u.y, 0.5 * u.z);
    }
    return convex_mesh(p, n);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorted p_qs and p_pqs of all poses, for comparing runs whose facet order
 * may differ. */
static int sorted_probs(const pd_static_result *r, double *qs, double *pqs)
{
    for (int i = 0; i < r->nposes; i++) {
        qs[i] = r->poses[i].p_qs;
        pqs[i] = r->poses[i].p_pqs;
    }
    qsort(qs, (size_t)r->nposes, sizeof *qs, cmp_double);
    qsort(pqs, (size_t)r->nposes, sizeof *pqs, cmp_double);
    return r->nposes;
}

static void test_invariance(void)
{
    test_rng rng = {2026};
    const double scales[] = {1e-3, 0.37, 1.0, 1e3};
    for (int trial = 0; trial < 6; trial++) {
        pd_mesh *m = random_convex(&rng, 24);
        pd_vec3 com = v3(rng_range(&rng, -0.2, 0.2), rng_range(&rng, -0.15, 0.15),
                         rng_range(&rng, -0.1, 0.1));
        for (int rule = 0; rule < 2; rule++) {
            pd_static_options o;
            pd_static_options_default(&o);
            o.topple = rule ? PD_TOPPLE_EDGE : PD_TOPPLE_DESCENT;
            pd_part *ref = part_of(pd_mesh_clone(m), &com, NULL);
            pd_static_result *r0 = ref ? estimate(ref, &o) : NULL;
            CHECK(r0 != NULL);
            if (!r0) {
                pd_part_free(ref);
                continue;
            }
            CHECK_NEAR(sum_qs(r0, 0), 1.0, 1e-12, "round-off");
            CHECK_NEAR(sum_qs(r0, 1), 1.0, 1e-12, "round-off");
            for (int i = 0; i < r0->nposes; i++)
                CHECK(r0->poses[i].p_pqs >= 0.0);
            double q0[64], p0[64], q1[64], p1[64];
            int n0 = sorted_probs(r0, q0, p0);
            for (size_t s = 0; s < sizeof scales / sizeof scales[0]; s++) {
                double R[3][3];
                rng_rotation(&rng, R);
                pd_vec3 t = v3(rng_range(&rng, -1e3, 1e3), rng_range(&rng, -1e3, 1e3),
                               rng_range(&rng, -1e3, 1e3));
                t = v3_scale(t, scales[s]);
                pd_mesh *mt = pd_mesh_clone(m);
                mesh_transform(mt, CR(R), scales[s], t);
                pd_vec3 ct = com;
                points_transform(&ct, 1, CR(R), scales[s], t);
                pd_part *pt = part_of(mt, &ct, NULL);
                pd_static_result *r1 = pt ? estimate(pt, &o) : NULL;
                CHECK(r1 != NULL);
                if (r1) {
                    CHECK_INT(r1->nposes, r0->nposes);
                    if (r1->nposes == n0) {
                        sorted_probs(r1, q1, p1);
                        double dq = 0, dp = 0;
                        for (int i = 0; i < n0; i++) {
                            dq = fmax(dq, fabs(q1[i] - q0[i]));
                            dp = fmax(dp, fabs(p1[i] - p0[i]));
                        }
                        CHECK_NEAR(dq, 0.0, 1e-12, "rigid motion and scale, round-off");
                        CHECK_NEAR(dp, 0.0, 1e-12, "rigid motion and scale, round-off");
                    }
                    /* Heights scale with the part; normals turn with it. */
                    const pd_pose *a = &r0->poses[0], *b = &r1->poses[0];
                    CHECK_REL(b->height, a->height * scales[s], 1e-9, "scale, round-off");
                    pd_vec3 nr = rot_apply(CR(R), a->normal);
                    CHECK_NEAR(v3_dist(nr, b->normal), 0.0, 1e-9, "rotation, round-off");
                }
                pd_static_result_free(r1);
                pd_part_free(pt);
            }
            pd_static_result_free(r0);
            pd_part_free(ref);
        }
        pd_mesh_free(m);
    }
}

/* Every option combination: sums to 1, no negative probability, and the
 * edge rule links only edge-adjacent facets. */
static void test_options(void)
{
    test_rng rng = {77};
    int vertex_links = 0;
    for (int trial = 0; trial < 10; trial++) {
        pd_mesh *m = random_convex(&rng, 30);
        pd_vec3 com = v3(rng_range(&rng, -0.3, 0.3), rng_range(&rng, -0.2, 0.2),
                         rng_range(&rng, -0.1, 0.1));
        pd_part *part = part_of(m, &com, NULL);
        CHECK(part != NULL);
        if (!part)
            continue;
        const pd_hull *h = part->hull;
        for (int combo = 0; combo < 8; combo++) {
            pd_static_options o;
            pd_static_options_default(&o);
            o.topple = combo & 1 ? PD_TOPPLE_EDGE : PD_TOPPLE_DESCENT;
            o.compare = combo & 2 ? PD_PQS_COMPARE_QS : PD_PQS_COMPARE_RAW;
            o.band = combo & 4 ? PD_PQS_BAND_EXACT : PD_PQS_BAND_RECT;
            pd_static_result *r = estimate(part, &o);
            CHECK(r != NULL);
            if (!r)
                continue;
            CHECK_NEAR(sum_qs(r, 0), 1.0, 1e-12, "round-off");
            CHECK_NEAR(sum_qs(r, 1), 1.0, 1e-12, "round-off");
            int negative = 0, nonadjacent = 0, rising = 0;
            for (int i = 0; i < r->nposes; i++)
                negative += r->poses[i].p_pqs < 0.0;
            for (int f = 0; f < r->nfacets; f++) {
                int nx = r->facets[f].next;
                if (nx < 0)
                    continue;
                rising += r->facets[nx].height >= r->facets[f].height;
                int adj = 0;
                for (int k = h->facet_start[f]; k < h->facet_start[f + 1]; k++)
                    adj |= h->facet_adj[k] == nx;
                nonadjacent += !adj;
            }
            CHECK_INT(negative, 0);
            CHECK_INT(rising, 0);
            if (o.topple == PD_TOPPLE_EDGE)
                CHECK_INT(nonadjacent, 0);
            else
                vertex_links += nonadjacent;
            pd_static_result_free(r);
        }
        pd_part_free(part);
    }
    /* docs/readings.md, "Toppling from a vertex region": on random polyhedra,
     * descent often lands on facets that share only a vertex; if it never
     * did, the pivot walk would be dead code. */
    CHECK(vertex_links > 0);
}

/* Descent against a brute-force oracle: projected subgradient steps of
 * 1e-4 rad on the support function, from each unstable facet's normal, must
 * settle at the stable facet the pivot walk predicts. */
static int numeric_descent(const pd_part *part, int f)
{
    const pd_hull *h = part->hull;
    pd_vec3 g = h->normal[f];
    const double step = 1e-4;
    for (int it = 0; it < 60000; it++) {
        int best = 0;
        double hmax = -1e300;
        for (int v = 0; v < h->nverts; v++) {
            double hv = v3_dot(v3_sub(h->verts[v], part->com), g);
            if (hv > hmax) {
                hmax = hv;
                best = v;
            }
        }
        pd_vec3 t = v3_sub(h->verts[best], part->com);
        t = v3_sub(t, v3_scale(g, v3_dot(t, g)));
        g = v3_unit(v3_sub(g, v3_scale(v3_unit(t), step)));
    }
    int near = -1;
    double best_angle = 1e-2;
    for (int k = 0; k < h->nfacets; k++)
        if (v3_angle(g, h->normal[k]) < best_angle) {
            best_angle = v3_angle(g, h->normal[k]);
            near = k;
        }
    return near;
}

static void test_descent_oracle(void)
{
    test_rng rng = {4242};
    int compared = 0, agree = 0;
    for (int trial = 0; trial < 4; trial++) {
        pd_mesh *m = random_convex(&rng, 16);
        pd_vec3 com = v3(rng_range(&rng, -0.3, 0.3), rng_range(&rng, -0.2, 0.2), 0.0);
        pd_part *part = part_of(m, &com, NULL);
        if (!part)
            continue;
        pd_static_result *r = estimate(part, NULL);
        if (r) {
            for (int f = 0; f < r->nfacets; f++) {
                if (r->facets[f].stable)
                    continue;
                int end = numeric_descent(part, f);
                if (end < 0)
                    continue; /* near a separatrix: the oracle did not settle */
                compared++;
                agree += end == r->facets[f].rest;
            }
        }
        pd_static_result_free(r);
        pd_part_free(part);
    }
    CHECK(compared >= 20);
    CHECK_INT(agree, compared);
}

/* --- PQS specifics --------------------------------------------------------------- */

static void test_pqs(void)
{
    /* Exact band against a closed form: triangle from the equator to the pole
     * with meridian sides, longitude width alpha: area alpha sin(eps). */
    double alpha = 0.7, area = 0;
    pd_vec3 A = v3(1, 0, 0), B = v3(cos(alpha), sin(alpha), 0), N = v3(0, 0, 1);
    const double eps[] = {1e-4, 0.1, 0.5, 1.2};
    for (int i = 0; i < 4; i++) {
        CHECK_STATUS(pd_band_area_exact(A, B, N, eps[i], &area), PD_OK);
        CHECK_REL(area, alpha * sin(eps[i]), 1e-10, "closed form, quadrature tolerance");
    }
    /* A general triangle: exact area tends to |a| eps for small eps (first
     * order: relative difference O(eps)), and to the triangle beyond N. */
    pd_vec3 a = v3_unit(v3(1, 0.2, 0.3)), b = v3_unit(v3(0.3, 1, 0.25)), n = v3_unit(v3(0.5, 0.6, 1));
    double small = 1e-5;
    CHECK_STATUS(pd_band_area_exact(a, b, n, small, &area), PD_OK);
    CHECK_REL(area, v3_angle(a, b) * small, 10 * small, "first-order expansion in eps");
    CHECK_STATUS(pd_band_area_exact(a, b, n, 1.5, &area), PD_OK);
    CHECK_REL(area, pd_solid_angle_triangle(a, b, n), 1e-14, "band covers the triangle");
    double prev = 0;
    int monotone = 1;
    for (double e = 0.01; e < 1.5; e += 0.01) {
        pd_band_area_exact(a, b, n, e, &area);
        monotone &= area >= prev;
        prev = area;
    }
    CHECK(monotone);

    /* epsilon 0: PQS is QS, to the bit. */
    pd_part *part = part_of(mesh_box(1, 2, 3), NULL, NULL);
    CHECK(part != NULL);
    if (part) {
        pd_static_options o;
        pd_static_options_default(&o);
        o.epsilon = 0;
        pd_static_result *r = estimate(part, &o);
        CHECK(r != NULL);
        for (int i = 0; r && i < r->nposes; i++)
            CHECK(r->poses[i].p_pqs == r->poses[i].p_qs);
        pd_static_result_free(r);
        /* Out-of-range epsilon is refused with a message. */
        pd_diag d;
        pd_diag_init(&d);
        o.epsilon = 2.0;
        r = NULL;
        CHECK_STATUS(pd_static_estimate(part, &o, &r, &d), PD_ERR_USAGE);
        CHECK(r == NULL && strstr(d.message, "epsilon") != NULL);
        /* A tall thin box with epsilon 90 degrees: bands exceed their
         * triangles and must be clipped, or probabilities go negative. */
        pd_part_free(part);
        part = part_of(mesh_box(0.1, 0.1, 5), NULL, NULL);
        o.epsilon = M_PI / 2;
        r = part ? estimate(part, &o) : NULL;
        CHECK(r != NULL);
        if (r) {
            for (int i = 0; i < r->nposes; i++)
                CHECK(r->poses[i].p_pqs >= 0.0);
            CHECK_NEAR(sum_qs(r, 1), 1.0, 1e-12, "round-off");
            /* Each end moves its whole solid angle to the sides. */
            const pd_pose *top = pose_with_normal(r, v3(0, 0, 1));
            CHECK(top != NULL && top->p_pqs < 1e-15);
        }
        pd_static_result_free(r);
        pd_part_free(part);
    }
}

/* --- hard cases ------------------------------------------------------------------ */

/* A box whose top face is fanned from one corner into thousands of slivers
 * through extra points on its edges. */
static pd_mesh *sliver_box(int per_edge)
{
    pd_mesh *m = calloc(1, sizeof *m);
    int nb = 4 * per_edge; /* boundary points of the top, corners included */
    m->verts = malloc(sizeof *m->verts * (size_t)(4 + nb));
    m->tris = malloc(sizeof *m->tris * (size_t)(2 * nb + 8)); /* 2 + 4 (k + 1) + nb - 2 */
    const double cx[4] = {-1, 1, 1, -1}, cy[4] = {-0.5, -0.5, 0.5, 0.5};
    for (int i = 0; i < 4; i++)
        m->verts[i] = v3(cx[i], cy[i], -0.25);
    for (int e = 0; e < 4; e++)
        for (int k = 0; k < per_edge; k++) {
            double t = (double)k / per_edge;
            int a = e, b = (e + 1) % 4;
            m->verts[4 + e * per_edge + k] =
                v3(cx[a] + t * (cx[b] - cx[a]), cy[a] + t * (cy[b] - cy[a]), 0.25);
        }
    m->nverts = 4 + nb;
    int nt = 0;
#define TRI(a, b, c) (m->tris[nt][0] = (a), m->tris[nt][1] = (b), m->tris[nt][2] = (c), nt++)
    TRI(0, 2, 1); /* bottom, seen from below */
    TRI(0, 3, 2);
    for (int e = 0; e < 4; e++) { /* sides: bottom edge to every top point on it */
        int a = e, b = (e + 1) % 4;
        int ta = 4 + e * per_edge, tb = 4 + ((e + 1) % 4) * per_edge;
        for (int k = 0; k < per_edge; k++) {
            int p = ta + k, q = k + 1 < per_edge ? ta + k + 1 : tb;
            TRI(a, q, p);
        }
        TRI(a, b, tb);
    }
    for (int k = 1; k + 1 < nb; k++) /* top: fan from the first corner */
        TRI(4, 4 + k, 4 + k + 1);
#undef TRI
    m->ntris = nt;
    return m;
}

static void compare_parts(pd_part *a, pd_part *b, double tol, const char *why)
{
    CHECK(a != NULL && b != NULL);
    if (!a || !b)
        return;
    CHECK_INT(b->hull->nfacets, a->hull->nfacets);
    pd_static_result *ra = estimate(a, NULL), *rb = estimate(b, NULL);
    CHECK(ra != NULL && rb != NULL);
    if (ra && rb && ra->nposes == rb->nposes) {
        double qa[64], pa[64], qb[64], pb[64];
        int n = sorted_probs(ra, qa, pa);
        sorted_probs(rb, qb, pb);
        for (int i = 0; i < n; i++) {
            CHECK_NEAR(qb[i], qa[i], tol, why);
            CHECK_NEAR(pb[i], pa[i], tol, why);
        }
    } else {
        CHECK(!"pose counts differ");
    }
    pd_static_result_free(ra);
    pd_static_result_free(rb);
}

static void test_hard_cases(void)
{
    /* Slivers and collinear points on edges give the plain box. */
    pd_mesh *sb = sliver_box(1000);
    CHECK_INT(sb->ntris, 2 + 4 * 1001 + 3998);
    pd_part *plain = part_of(mesh_box(2, 1, 0.5), NULL, NULL);
    pd_part *sliver = part_of(sb, NULL, NULL);
    compare_parts(plain, sliver, 1e-12, "same solid, round-off");
    if (sliver) {
        CHECK_INT(sliver->hull->nfacets, 6);
        CHECK_INT(sliver->hull->nverts, 8);
    }
    pd_part_free(sliver);

    /* Misoriented triangles are flipped back, with a warning. */
    pd_mesh *mis = mesh_box(2, 1, 0.5);
    for (int t = 0; t < mis->ntris; t += 3) {
        int s = mis->tris[t][1];
        mis->tris[t][1] = mis->tris[t][2];
        mis->tris[t][2] = s;
    }
    pd_diag d;
    pd_diag_init(&d);
    pd_part *fixed = part_of(mis, NULL, &d);
    CHECK(d.nwarnings >= 1);
    compare_parts(plain, fixed, 1e-12, "same solid, round-off");
    pd_part_free(fixed);

    /* Duplicate and near-duplicate vertices: a triangle soup whose later
     * copies of each corner are jittered by 1e-9 of the size, far below the
     * weld tolerance, welds back onto the first (exact) copies: the box. */
    pd_mesh *box = mesh_box(2, 1, 0.5);
    pd_mesh *soup = calloc(1, sizeof *soup);
    soup->nverts = 3 * box->ntris;
    soup->ntris = box->ntris;
    soup->verts = malloc(sizeof *soup->verts * (size_t)soup->nverts);
    soup->tris = malloc(sizeof *soup->tris * (size_t)soup->ntris);
    test_rng rng = {99};
    int seen[64] = {0};
    for (int t = 0; t < box->ntris; t++)
        for (int c = 0; c < 3; c++) {
            int v = box->tris[t][c];
            pd_vec3 jitter = v3_scale(rng_unit_vector(&rng), seen[v]++ ? 2.3e-9 : 0.0);
            soup->verts[3 * t + c] = v3_add(box->verts[v], jitter);
            soup->tris[t][c] = 3 * t + c;
        }
    pd_mesh_free(box);
    pd_part *welded = part_of(soup, NULL, NULL);
    compare_parts(plain, welded, 1e-12, "same solid after welding, round-off");
    pd_part_free(welded);
    pd_part_free(plain);

    /* A box whose top is a shallow roof with its ridge off centre: at a
     * crease of 1e-7 rad the two slopes are one facet within the plane
     * tolerance (PD_TOL_PLANE_REL) and the part is the box; at 1e-4 rad they
     * stay two, the com's side is stable and the other topples onto it, so
     * the box's top probability is kept in either case. */
    const double creases[] = {1e-7, 1e-4};
    for (int c = 0; c < 2; c++) {
        double rise = creases[c] / (1 / 0.75 + 1 / 1.25);
        pd_vec3 p[10];
        int n = pts_box(2, 1, 0.5, p);
        p[n++] = v3(-0.25, -0.5, 0.25 + rise);
        p[n++] = v3(-0.25, 0.5, 0.25 + rise);
        pd_vec3 com = v3(0, 0, 0);
        pd_part *roof = part_of(convex_mesh(p, n), &com, NULL);
        CHECK(roof != NULL);
        if (!roof)
            continue;
        CHECK_INT(roof->hull->nfacets, c == 0 ? 6 : 7);
        pd_static_result *r = estimate(roof, NULL);
        if (r) {
            CHECK_INT(r->nposes, 6);
            double top = rect_omega(2, 1, 0.25) / (4 * M_PI);
            int found = 0;
            for (int i = 0; i < r->nposes; i++)
                if (r->poses[i].normal.z > 0.5) {
                    found = 1;
                    CHECK_NEAR(r->poses[i].p_qs, top, 10 * creases[c], "first order in the crease");
                }
            CHECK(found);
        }
        pd_static_result_free(r);
        pd_part_free(roof);
    }

    /* Noisy prisms: a cap split by noise into facets a hair out of plane,
     * some merged back into fitted planes, so facet heights are known to
     * PD_TOL_PLANE_REL L only; 9 of these 300 failed (rise tolerance 1e-12 L) with a
     * quasi-static link "raising" the centre of mass by ~1e-8 L. Every one
     * must now give a table whose probabilities sum to 1 (round-off). */
    {
        test_rng nr = {2026};
        int failed = 0, tried = 0;
        for (int i = 0; i < 300; i++) {
            pd_vec3 p[64];
            int sides = 5 + (int)(rng_uniform(&nr) * 4);
            double radius = 2e-3, height = radius * rng_range(&nr, 0.5, 3.0);
            double noise = radius * pow(10.0, rng_range(&nr, -7.0, -4.0));
            int n = pts_prism(sides, radius, height, p);
            for (int k = 0; k < n; k++)
                p[k] = v3_add(p[k], v3_scale(rng_unit_vector(&nr), noise * rng_uniform(&nr)));
            pd_vec3 com = v3(rng_range(&nr, -0.03, 0.03) * radius, rng_range(&nr, -0.03, 0.03) * radius,
                             rng_range(&nr, -0.03, 0.03) * height);
            pd_mesh *m = convex_mesh(p, n);
            if (!m)
                continue;
            tried++;
            pd_part *part = part_of(m, &com, NULL);
            pd_static_result *r = part ? estimate(part, NULL) : NULL;
            failed += !r || fabs(sum_qs(r, 0) - 1.0) > 1e-12;
            pd_static_result_free(r);
            pd_part_free(part);
        }
        CHECK(tried >= 290);
        CHECK_INT(failed, 0);
    }

    /* A 100k-vertex hull (points on an ellipsoid), centre of mass off centre. */
    {
        enum { N = 100000 };
        pd_vec3 *p = malloc(sizeof *p * N);
        test_rng r2 = {5};
        for (int i = 0; i < N; i++) {
            pd_vec3 u = rng_unit_vector(&r2);
            p[i] = v3(u.x, 0.7 * u.y, 0.45 * u.z);
        }
        pd_hull *h = NULL;
        CHECK_STATUS(pd_hull_build(p, N, &h, NULL), PD_OK);
        if (h) {
            pd_vec3 c = v3(0.1, -0.05, 0.02);
            pd_part *big = part_of(mesh_of_hull(h), &c, NULL);
            /* Near-flat neighbours may merge and drop a few points, rarely. */
            CHECK(big != NULL && big->hull->nverts > N - N / 1000);
            for (int rule = 0; big && rule < 2; rule++) {
                pd_static_options o;
                pd_static_options_default(&o);
                o.topple = rule ? PD_TOPPLE_EDGE : PD_TOPPLE_DESCENT;
                pd_static_result *r = estimate(big, &o);
                CHECK(r != NULL);
                if (r) {
                    CHECK(r->nposes >= 1);
                    CHECK_NEAR(sum_qs(r, 0), 1.0, 1e-12, "round-off over 2e5 facets");
                    CHECK_NEAR(sum_qs(r, 1), 1.0, 1e-12, "round-off over 2e5 facets");
                }
                pd_static_result_free(r);
            }
            pd_part_free(big);
            pd_hull_free(h);
        }
        free(p);
    }
}

static void test_pose_order(void)
{
    /* Ties order by normal, lexicographically ascending: a 1 x 2 x 3 box
     * rests most often on its 2 x 3 faces, -x listed before +x; the table is
     * by descending p_qs. */
    pd_part *part = part_of(mesh_box(1, 2, 3), NULL, NULL);
    pd_static_result *r = part ? estimate(part, NULL) : NULL;
    CHECK(r != NULL);
    if (r) {
        CHECK_INT(r->nposes, 6);
        CHECK(r->poses[0].normal.x < -0.5 && r->poses[1].normal.x > 0.5);
        for (int i = 1; i < r->nposes; i++)
            CHECK(r->poses[i].p_qs <= r->poses[i - 1].p_qs * (1 + PD_TOL_PROB_TIE_REL));
    }
    pd_static_result_free(r);
    pd_part_free(part);
}

/* The transform of each pose against what it claims: applied to the part
 * in its file's frame, the pose's hull facet lies on z = 0 facing down (its
 * outward normal -z), no hull vertex is below the floor, and the centre of
 * mass stands at the pose's height above a point of the facet. On random
 * convex parts turned, scaled from 1e-3 to 1e3 and moved far off the
 * origin (pd_part.origin nonzero), and on a box along the axes (the
 * horizontal facets' fixed x axis). Tolerances relative to the part's size
 * L: its facets are planar to PD_TOL_PLANE_REL L (merged facets), the rest
 * is round-off of coordinates up to 1e3 L from the origin. */
static void check_pose_transforms(const pd_part *part, const pd_static_result *r)
{
    const pd_hull *h = part->hull;
    double L = part->size, far = v3_norm(part->origin) + L;
    double tol = 2.0 * PD_TOL_PLANE_REL * L + 1e-12 * far;
    for (int i = 0; i < r->nposes; i++) {
        const pd_pose *p = &r->poses[i];
        double T[16];
        CHECK_STATUS(pd_pose_transform(part, p, T, NULL), PD_OK);
        double R[3][3];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                R[a][b] = T[4 * a + b];
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                double d = R[a][0] * R[b][0] + R[a][1] * R[b][1] + R[a][2] * R[b][2];
                CHECK_NEAR(d, a == b ? 1.0 : 0.0, 1e-14, "orthonormal rows, round-off");
            }
        pd_vec3 cx = v3(R[0][0], R[0][1], R[0][2]), cy = v3(R[1][0], R[1][1], R[1][2]);
        pd_vec3 cz = v3(R[2][0], R[2][1], R[2][2]);
        CHECK_NEAR(v3_dot(v3_cross(cx, cy), cz), 1.0, 1e-14, "a rotation: det +1, round-off");
        CHECK(T[2] == 0.0 && T[12] == 0.0 && T[13] == 0.0 && T[14] == 0.0 && T[15] == 1.0);
        /* The facet's outward normal turns to -z. */
        pd_vec3 n = rot_apply(CR(R), h->normal[p->facet]);
        CHECK_NEAR(v3_dist(n, v3(0, 0, -1)), 0.0, 1e-12, "rotation of a unit vector, round-off");
        double lowest = HUGE_VAL, fz = 0.0;
        for (int v = 0; v < h->nverts; v++) {
            pd_vec3 w = rot_apply(CR(R), v3_add(h->verts[v], part->origin));
            lowest = fmin(lowest, w.z + T[11]);
        }
        CHECK_NEAR(lowest, 0.0, tol, "the lowest hull vertex on the floor, round-off");
        pd_vec3 poly[64];
        int nc = h->facet_start[p->facet + 1] - h->facet_start[p->facet];
        for (int c = 0; c < nc && c < 64; c++) {
            int v = h->facet_vert[h->facet_start[p->facet] + c];
            poly[c] = rot_apply(CR(R), v3_add(h->verts[v], part->origin));
            poly[c].z += T[11];
            fz = fmax(fz, fabs(poly[c].z));
        }
        CHECK_NEAR(fz, 0.0, tol, "the facet on the floor: its plane tolerance");
        pd_vec3 com = rot_apply(CR(R), v3_add(part->com, part->origin));
        com.z += T[11];
        CHECK_NEAR(com.z, p->height, tol, "the pose's height, plane tolerance");
        CHECK(com.z > 0.0);
        /* Above the facet: on the inner side of each edge, the loop being
         * clockwise seen from above once the facet faces down. */
        double worst = HUGE_VAL;
        for (int c = 0; c < nc && c < 64; c++) {
            pd_vec3 a = poly[c], b = poly[(c + 1) % nc];
            double e = hypot(b.x - a.x, b.y - a.y);
            double side = ((a.x - com.x) * (b.y - com.y) - (a.y - com.y) * (b.x - com.x)) / e;
            worst = fmin(worst, -side);
        }
        CHECK(worst > -PD_TOL_KNIFE_REL * L - tol);
    }
}

static void test_pose_transform(void)
{
    test_rng rng = {20261127};
    const double scales[] = {1e-3, 1.0, 1e3};
    for (int trial = 0; trial < 6; trial++) {
        pd_mesh *m = random_convex(&rng, 24);
        double R[3][3];
        rng_rotation(&rng, R);
        double s = scales[trial % 3];
        pd_vec3 t = v3_scale(v3(rng_range(&rng, -1e3, 1e3), rng_range(&rng, -1e3, 1e3),
                                rng_range(&rng, -1e3, 1e3)), s);
        mesh_transform(m, CR(R), s, t);
        pd_part *part = part_of(m, NULL, NULL);
        pd_static_result *r = part ? estimate(part, NULL) : NULL;
        CHECK(r != NULL && r->nposes > 0);
        if (r)
            check_pose_transforms(part, r);
        if (r && trial == 0)
            CHECK(v3_norm(part->origin) > 0.0);
        pd_static_result_free(r);
        pd_part_free(part);
    }
    pd_vec3 pts[8];
    int np = pts_box(0.03, 0.02, 0.01, pts);
    pd_part *box = part_of(convex_mesh(pts, np), NULL, NULL);
    pd_static_result *r = box ? estimate(box, NULL) : NULL;
    CHECK(r != NULL && r->nposes == 6);
    if (!r) {
        pd_part_free(box);
        return;
    }
    check_pose_transforms(box, r);
    /* Resting on its largest face, z down: x stays (1, 0, 0) up to sign
     * conventions of trimesh's frame, exactly. */
    const pd_pose *down = pose_with_normal(r, v3(0, 0, -1));
    double T[16];
    CHECK(down && pd_pose_transform(box, down, T, NULL) == PD_OK && T[0] == 1.0 && T[1] == 0.0);
    /* Refusals leave the transform alone. */
    double before[16];
    for (int k = 0; k < 16; k++)
        T[k] = before[k] = -7.0;
    pd_pose bad = r->poses[0];
    pd_diag d;
    pd_diag_init(&d);
    bad.normal = v3_scale(bad.normal, 2.0);
    CHECK_STATUS(pd_pose_transform(box, &bad, T, &d), PD_ERR_USAGE);
    CHECK(strstr(d.message, "not a unit vector") != NULL);
    bad.normal = v3(NAN, 0, 0);
    CHECK_STATUS(pd_pose_transform(box, &bad, T, &d), PD_ERR_NONFINITE);
    bad = r->poses[0];
    bad.facet = box->hull->nfacets;
    CHECK_STATUS(pd_pose_transform(box, &bad, T, &d), PD_ERR_RANGE);
    CHECK(memcmp(T, before, sizeof T) == 0);
    pd_static_result_free(r);
    pd_part_free(box);
}

void suite_static(void)
{
    test_solid_angle();
    test_boxes();
    test_prisms();
    test_platonic();
    test_printed_symmetry();
    test_knife_edge();
    test_invariance();
    test_options();
    test_descent_oracle();
    test_pqs();
    test_hard_cases();
    test_pose_order();
    test_pose_transform();
}
