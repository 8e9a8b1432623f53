/* test_flat_rest.c: the flat-facet settling test (src/settle/flat_rest.c): its
 * facet data in closed form and under placement, its rule on states built
 * by hand, and its outcomes against drops run to the end without it. */
#include <stdlib.h>
#include "check.h"
#include "drop_fixture.h"
#include "sim/drop.h"
#include "settle/flat_rest.h"
#include "base/mat3.h"
#include "posedrop/posedrop.h"
#include "base/quat.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"
#include "settle/settle_tol.h"

static void test_box_facets(void)
{
    /* A 1 x 2 x 3 cm box: on the face across axis k the centre of mass is
     * half the box's k-th edge high, its foot is half the shorter other edge
     * from the boundary and half the face's diagonal from the corners; the
     * moment about the normal is m (a^2 + b^2) / 12 and the normal is a
     * principal axis (tilt 0). Round-off of sums of ~10 terms of size L: 1e-12. */
    pd_scene sc;
    drop_fixture fx;
    const pd_body *b = drop_setup_box(&fx, &sc, 0.3);
    if (!b)
        return;
    const double edge[3] = {0.01, 0.02, 0.03};
    const pd_hull *hull = fx.model->hull;
    CHECK_INT(hull->nfacets, 6);
    for (int f = 0; f < hull->nfacets; f++) {
        pd_vec3 n = hull->normal[f];
        int k = fabs(n.x) > 0.5 ? 0 : fabs(n.y) > 0.5 ? 1 : 2;
        double a = edge[(k + 1) % 3], c = edge[(k + 2) % 3];
        const pd_flat_facet *F = &fx.model->settle.flat[f];
        CHECK_NEAR(F->h, 0.5 * edge[k], 1e-12 * 0.03, "closed form, round-off");
        CHECK_NEAR(F->inside, 0.5 * fmin(a, c), 1e-12 * 0.03, "closed form, round-off");
        CHECK_NEAR(F->reach, 0.5 * hypot(a, c), 1e-12 * 0.03, "closed form, round-off");
        CHECK_REL(F->inn, b->mass * (a * a + c * c) / 12.0, 1e-12, "closed form, round-off");
        CHECK_NEAR(F->tilt, 0.0, 1e-12 * F->inn, "principal axis, round-off");
    }
    drop_teardown(&fx);
}

/* Sum over stable facets of (h, inside, reach) per size and of (inn, tilt)
 * per m L^2: order-free summaries that placement must not change. */
static void flat_summary(pd_mesh *mesh, double L, double out[5])
{
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    for (int i = 0; i < 5; i++)
        out[i] = NAN;
    if (!drop_setup(&fx, mesh, &sc))
        return;
    const pd_body *b = (fx.model)->body;
    for (int i = 0; i < 5; i++)
        out[i] = 0.0;
    for (int f = 0; f < fx.model->hull->nfacets; f++) {
        const pd_flat_facet *F = &fx.model->settle.flat[f];
        if (!(F->inside > 0.0))
            continue;
        out[0] += F->h / L;
        out[1] += F->inside / L;
        out[2] += F->reach / L;
        out[3] += F->inn / (b->mass * L * L);
        out[4] += F->tilt / (b->mass * L * L);
    }
    drop_teardown(&fx);
}

static void test_placement(void)
{
    /* An irregular convex part (random points on a squashed sphere, so the
     * facets' normals are not principal: tilt > 0): the facet data scale with
     * the part and do not see where or how it is placed. Tolerance: 1e-9,
     * the round-off of mass properties from ~100 triangles, with margin. */
    test_rng r = {7};
    pd_vec3 pts[40];
    for (int i = 0; i < 40; i++) {
        pd_vec3 u = rng_unit_vector(&r);
        pts[i] = v3(u.x, 0.6 * u.y, 0.35 * u.z);
    }
    double ref[5];
    flat_summary(convex_mesh(pts, 40), 1.0, ref);
    CHECK(ref[4] > 1e-3); /* not a box in disguise */
    const double scales[3] = {1e-3, 1.0, 1e3};
    for (int k = 0; k < 3; k++) {
        double R[3][3], got[5];
        rng_rotation(&r, R);
        pd_mesh *m = convex_mesh(pts, 40);
        if (m)
            mesh_transform(m, CONST_M3(R), scales[k], v3(5.0 * scales[k], -2.0 * scales[k], 0.5));
        flat_summary(m, scales[k], got);
        for (int i = 0; i < 5; i++)
            CHECK_REL(got[i], ref[i], 1e-9, "rotation, translation and scale invariance; round-off");
    }
}

/* The part lying flat on facet f, sliding at v and spinning about
 * the vertical at spin, plus a rocking rate about a horizontal axis. */
static pd_state lying_flat(const pd_sim_model *m, int f, pd_vec3 v, double spin, double rock)
{
    const pd_flat_facet *F = &m->settle.flat[f];
    pd_quat q = quat_onto_down(F->n);
    pd_state st = {v3(0, 0, F->h), q, v, quat_rotate_inv(q, v3(rock, 0, spin))};
    return st;
}

static void test_rule(void)
{
    /* The 1 cm cube at mu 0.3 on its face: friction needs the centre of
     * pressure 0.3 h = 1.5 mm off the foot, 5 mm from the edges, whatever
     * the slide and spin (the cube's every axis is principal). The edge then
     * holds like one at 3.5 mm: barrier sqrt(3.5^2 + 5^2) - 5 = 1.10 mm, of
     * which rocking may take 1/PD_FLAT_SAFETY, less the rest fall (1.7 um). */
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    if (!drop_setup(&fx, mesh_box(0.01, 0.01, 0.01), &sc))
        return;
    const pd_sim_model *m = fx.model;
    const pd_body *b = m->body;
    double g = sc.gravity, rf = m->settle.rest_fall;
    double barrier = sqrt(0.0035 * 0.0035 + 0.005 * 0.005) - 0.005;
    double allowed = barrier / PD_FLAT_SAFETY - rf;
    /* Rocking rate whose energy per unit weight is e: I w^2 / 2 = m g e. */
    double I = b->moment[0];
    for (int f = 0; f < 6; f++) {
        pd_state fast = lying_flat(m, f, v3(2.0, -1.0, 0.0), 300.0, 0.0);
        CHECK(pd_flat_settled(m->settle.flat, b, &fast, f, g, 0.3, rf));
        CHECK(!pd_flat_settled(m->settle.flat, b, &fast, f, g, 1.0, rf)); /* mu h = inside */
        double w_in = sqrt(2.0 * b->mass * g * 0.99 * allowed / I);
        double w_out = sqrt(2.0 * b->mass * g * 1.01 * allowed / I);
        pd_state in = lying_flat(m, f, v3(0.5, 0, 0), 0.0, w_in);
        pd_state out = lying_flat(m, f, v3(0.5, 0, 0), 0.0, w_out);
        CHECK(pd_flat_settled(m->settle.flat, b, &in, f, g, 0.3, rf));
        CHECK(!pd_flat_settled(m->settle.flat, b, &out, f, g, 0.3, rf));
        /* Lifted by the same energy: the same verdicts. */
        in.w = out.w = v3(0, 0, 0);
        in.x.z += 0.99 * allowed;
        out.x.z += 1.01 * allowed;
        CHECK(pd_flat_settled(m->settle.flat, b, &in, f, g, 0.3, rf));
        CHECK(!pd_flat_settled(m->settle.flat, b, &out, f, g, 0.3, rf));
    }
    drop_teardown(&fx);
}

/* pd_flat_height_max: with the centre of mass at or above it no facet
 * passes, lying level and at rest (the test's most lenient state) or turned
 * and moving at random, even at mu 0 and no rest fall (its most lenient
 * settings); and it is tight: lying level and at rest 2% of the way below
 * it, on the facet that sets it, the part passes (the exact test takes a
 * height up to PD_FLAT_EARLY_SHARE, 0.99, of the way to it, so 0.98 must
 * pass, and would not with a height_max more than about 1% too high; one
 * too low fails the first check). */
static void height_max_check(pd_mesh *mesh)
{
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    if (!drop_setup(&fx, mesh, &sc))
        return;
    const pd_sim_model *m = fx.model;
    const pd_body *b = m->body;
    int nf = m->hull->nfacets;
    double zmax = pd_flat_height_max(m->settle.flat, nf), g = sc.gravity;
    CHECK(isfinite(zmax) && zmax > 0.0);
    test_rng rng = {7};
    int passed = 0;
    /* The first state exactly at zmax, the others up to 1.5 zmax; moving at
     * up to 0.5 m/s and spinning at up to 50 rad/s, a drop's range. */
    for (int t = 0; t < 200; t++) {
        pd_vec3 axis = rng_unit_vector(&rng);
        pd_state s = {v3(0, 0, zmax * (1.0 + rng_range(&rng, 0.0, 0.5) * (t > 0))),
                      quat_axis_angle(axis, rng_range(&rng, 0.0, M_PI)),
                      v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.0, 0.5)),
                      v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.0, 50.0))};
        for (int f = 0; f < nf; f++)
            passed += pd_flat_settled(m->settle.flat, b, &s, f, g, 0.0, 0.0);
    }
    int tight = 0;
    for (int f = 0; f < nf; f++) {
        const pd_flat_facet *F = &m->settle.flat[f];
        if (!(F->inside > 0.0))
            continue;
        pd_state s = lying_flat(m, f, v3(0, 0, 0), 0.0, 0.0);
        s.x.z = zmax;
        passed += pd_flat_settled(m->settle.flat, b, &s, f, g, 0.0, 0.0);
        s.x.z = F->h + 0.98 * (zmax - F->h);
        tight |= pd_flat_settled(m->settle.flat, b, &s, f, g, 0.0, 0.0);
    }
    CHECK_INT(passed, 0);
    CHECK(tight);
    drop_teardown(&fx);
}

static void test_height_max(void)
{
    height_max_check(mesh_box(0.01, 0.01, 0.01));
    height_max_check(mesh_box(0.01, 0.02, 0.03));
    height_max_check(mesh_prism(32, 0.01, 0.01));
}

/* Runs n drops of mesh in the default scene with the test and again with it
 * switched off (no facet counts as stable for it): every outcome must agree,
 * and the test must have ended at least min_earlier of them early. */
static void agree(const char *name, pd_mesh *mesh, long n, long min_earlier)
{
    pd_scene sc;
    pd_scene_default(&sc);
    drop_fixture fx;
    if (!drop_setup(&fx, mesh, &sc))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    int nf = fx.model->hull->nfacets;
    pd_trial *with = calloc((size_t)n, sizeof *with);
    double *inside = malloc(sizeof *inside * (size_t)nf);
    if (!with || !inside) {
        CHECK(with && inside);
        free(with);
        free(inside);
        drop_teardown(&fx);
        return;
    }
    long gain = 0, fb = 0, differ = 0, earlier = 0, coll[2] = {0, 0};
    for (long d = 0; d < n; d++)
        pd_drop_run(fx.model, fx.work, &sc, &o, d, NULL, &with[d], &gain, &fb);
    for (int f = 0; f < nf; f++) {
        inside[f] = fx.model->settle.flat[f].inside;
        fx.model->settle.flat[f].inside = 0.0;
    }
    for (long d = 0; d < n; d++) {
        pd_trial t;
        pd_drop_run(fx.model, fx.work, &sc, &o, d, NULL, &t, &gain, &fb);
        differ += t.pose != with[d].pose || t.end != with[d].end;
        earlier += with[d].collisions < t.collisions;
        coll[0] += with[d].collisions;
        coll[1] += t.collisions;
    }
    CHECK_INT(differ, 0);
    CHECK(earlier >= min_earlier);
    pd_note("flat_rest: %s, %ld drops: %ld decided earlier by the flat test, none differ in outcome "
           "(%ld); collisions per drop %.1f with it, %.1f without\n",
           name, n, earlier, differ, (double)coll[0] / n, (double)coll[1] / n);
    for (int f = 0; f < nf; f++)
        fx.model->settle.flat[f].inside = inside[f];
    free(inside);
    free(with);
    drop_teardown(&fx);
}

static void test_agreement(void)
{
    /* The floors on "earlier" are a third of what was measured (cube 183,
     * box 24 of 300, coin 7 of 150): they only keep the comparison from
     * passing vacuously. Outside make check the same comparison over nine
     * parts (these three, the paper's four, the shipped nut and block) and
     * five scenes (mu 0.1 to 0.5, restitution 0.1 to 0.6, 0.3 m, bootstrap),
     * 200 drops each, changed no outcome and ended 1071 drops earlier. */
    agree("1 cm cube", mesh_box(0.01, 0.01, 0.01), 300, 60);
    agree("1 x 2 x 3 cm box", mesh_box(0.01, 0.02, 0.03), 300, 8);
    agree("32-gon coin", mesh_prism(32, 0.01, 0.01), 150, 2);
}

void suite_flat_rest(void)
{
    test_box_facets();
    test_placement();
    test_rule();
    test_height_max();
    test_agreement();
}
