/* test_part.c: building the part model: what is accepted, what is refused
 * and with which status, and that the model is placed where the mesh is. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "files.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"
#include "hull/hull_internal.h"
#include "mesh/mesh_internal.h"
#include "part/part_tol.h"

static pd_part *const SENTINEL = (pd_part *)&SENTINEL;

/* pd_part_build expecting a failure: the status, a message, output untouched. */
static void expect_refused(const pd_mesh *m, const pd_part_options *o, pd_status want,
                           const char *mention)
{
    pd_diag d;
    pd_diag_init(&d);
    pd_part *p = SENTINEL;
    CHECK_STATUS(pd_part_build(m, o, &p, &d), want);
    CHECK(p == SENTINEL);
    if (!strstr(d.message, mention))
        printf("     message '%s' lacks '%s'\n", d.message, mention);
    CHECK(strstr(d.message, mention) != NULL);
}

/* A tetrahedron's three faces without the fourth: open. */
static pd_mesh *open_tetra(void)
{
    pd_mesh *m = calloc(1, sizeof *m);
    m->nverts = 4;
    m->verts = malloc(sizeof *m->verts * 4);
    m->verts[0] = v3(0, 0, 0);
    m->verts[1] = v3(1, 0, 0);
    m->verts[2] = v3(0, 1, 0);
    m->verts[3] = v3(0, 0, 1);
    m->ntris = 3;
    m->tris = malloc(sizeof *m->tris * 3);
    const int t[3][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}};
    memcpy(m->tris, t, sizeof t);
    return m;
}

static void test_box(void)
{
    pd_mesh *m = mesh_box(0.04, 0.02, 0.01);
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    if (p) {
        CHECK_INT(p->closed, 1);
        CHECK_INT(p->mass_known, 1);
        CHECK_NEAR(v3_norm(p->com), 0.0, 1e-18, "centre of a symmetric box, round-off");
        CHECK_REL(p->mass.volume, 0.04 * 0.02 * 0.01, 1e-12, "closed form");
        CHECK_REL(p->size, sqrt(0.04 * 0.04 + 0.02 * 0.02 + 0.01 * 0.01), 1e-15, "diagonal");
        CHECK_INT(p->hull->nfacets, 6);
    }
    pd_part_free(p);

    /* Far from the origin the part model moves with the mesh, without losing
     * the digits of its own size. */
    pd_vec3 t = v3(1e6, -2e6, 3e5);
    double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh_transform(m, CR(I), 1.0, t);
    p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    if (p) {
        CHECK_NEAR(v3_dist(v3_add(p->origin, p->com), t), 0.0, 1e-9,
                   "coordinates of 1e6 carry 1e-10 round-off");
        /* The part's frame keeps positions within 1.5 L of its origin per
         * axis (part.c), whatever the mesh's placement. */
        double far = 0.0;
        for (int i = 0; i < p->mesh->nverts; i++)
            far = fmax(far, fmax(fabs(p->mesh->verts[i].x),
                                 fmax(fabs(p->mesh->verts[i].y), fabs(p->mesh->verts[i].z))));
        CHECK(far <= 1.5 * p->size);
    }
    pd_part_free(p);

    /* A given centre of mass replaces the computed one. */
    pd_part_options o;
    pd_part_options_default(&o);
    o.com_given = 1;
    o.com = v3_add(t, v3(0.01, 0.005, -0.002));
    p = NULL;
    CHECK_STATUS(pd_part_build(m, &o, &p, NULL), PD_OK);
    if (p) {
        CHECK(v3_dist(v3_add(p->com, p->origin), o.com) == 0.0); /* moves by exact differences */
        CHECK_INT(p->mass_known, 1);
    }
    pd_part_free(p);
    pd_mesh_free(m);
}

static void test_refusals(void)
{
    pd_part_options o;
    pd_part_options_default(&o);

    /* Open mesh: refused without a centre of mass, used with one (warned). */
    pd_mesh *open = open_tetra();
    expect_refused(open, NULL, PD_ERR_NOT_CLOSED, "");
    o.com_given = 1;
    o.com = v3(0.2, 0.2, 0.2);
    pd_diag d;
    pd_diag_init(&d);
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(open, &o, &p, &d), PD_OK);
    CHECK_INT(d.nwarnings, 1);
    CHECK_INT((int)strlen(d.message), 0);
    if (p) {
        CHECK_INT(p->closed, 0);
        CHECK_INT(p->mass_known, 0);
    }
    pd_part_free(p);

    /* Centre of mass outside the hull, on it, and just inside it. */
    o.com = v3(1, 1, 1);
    expect_refused(open, &o, PD_ERR_COM_OUTSIDE, "outside the convex hull");
    o.com = v3(0.2, 0.2, 0.0);
    expect_refused(open, &o, PD_ERR_COM_OUTSIDE, "on the convex hull");
    /* The bound is PD_TOL_COM_INSIDE_REL of the size (sqrt 3 here): half of
     * it inside is still "on", twice of it inside is accepted. */
    double tol = PD_TOL_COM_INSIDE_REL * sqrt(3.0);
    o.com = v3(0.2, 0.2, 0.5 * tol);
    expect_refused(open, &o, PD_ERR_COM_OUTSIDE, "on the convex hull");
    o.com = v3(0.2, 0.2, 2 * tol);
    p = NULL;
    CHECK_STATUS(pd_part_build(open, &o, &p, NULL), PD_OK);
    pd_part_free(p);
    pd_mesh_free(open);

    /* Degenerate geometry gets its own status. */
    pd_mesh *flat = open_tetra();
    flat->verts[3] = v3(1, 1, 0);
    expect_refused(flat, NULL, PD_ERR_COPLANAR, "");
    for (int i = 0; i < 4; i++)
        flat->verts[i] = v3(i, 2 * i, -i);
    expect_refused(flat, NULL, PD_ERR_COLLINEAR, "");
    flat->nverts = 3;
    flat->ntris = 1;
    expect_refused(flat, NULL, PD_ERR_TOO_FEW_POINTS, "");
    pd_mesh_free(flat);

    /* Non-finite coordinates. */
    pd_mesh *bad = mesh_box(1, 1, 1);
    bad->verts[2].y = NAN;
    expect_refused(bad, NULL, PD_ERR_NONFINITE, "");
    pd_mesh_free(bad);

    /* NULL arguments. */
    pd_part *q = SENTINEL;
    CHECK_STATUS(pd_part_build(NULL, NULL, &q, NULL), PD_ERR_USAGE);
    CHECK(q == SENTINEL);
}

static void test_orientation(void)
{
    /* The input mesh is const: flipping happens on the part's copy. */
    pd_mesh *m = mesh_box(1, 2, 3);
    int t0 = m->tris[0][1];
    int s = m->tris[0][1];
    m->tris[0][1] = m->tris[0][2];
    m->tris[0][2] = s;
    pd_diag d;
    pd_diag_init(&d);
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, &d), PD_OK);
    CHECK_INT(d.nwarnings, 1);
    CHECK(m->tris[0][2] == t0);
    if (p)
        CHECK_REL(p->mass.volume, 6.0, 1e-12, "re-oriented box, closed form");
    pd_part_free(p);
    pd_mesh_free(m);
}

/* parts/square_black_button.off with one top corner of its flange moved through
 * the part to y = -1 m (a case once reported): a spike folded back through the body,
 * whose far side counts negatively. The static estimate took it, the drops
 * refused it; now the part build refuses it, saying why (docs/limits.md
 * gives its moments), and with a given centre of mass both take it. */
static void test_folded_through(void)
{
    char *text = slurp("parts/square_black_button.off");
    char *at = text ? strstr(text, "\n0.0031805 0.0047475 0.00529\n") : NULL;
    CHECK(at != NULL);
    if (!at) {
        free(text);
        return;
    }
    size_t n = strlen(text);
    char *moved = malloc(n + 16);
    size_t head = (size_t)(at - text) + 1;
    memcpy(moved, text, head);
    int len = sprintf(moved + head, "0.0031805 -1 0.00529");
    strcpy(moved + head + (size_t)len, at + 1 + strlen("0.0031805 0.0047475 0.00529"));
    pd_mesh *m = NULL, *orig = NULL;
    CHECK_STATUS(pd_mesh_parse(moved, strlen(moved), "sbb.off", NULL, &m, NULL), PD_OK);
    CHECK_STATUS(pd_mesh_parse(text, n, "sbb.off", NULL, &orig, NULL), PD_OK);
    free(text);
    free(moved);
    if (!m || !orig) {
        pd_mesh_free(m);
        pd_mesh_free(orig);
        return;
    }
    CHECK_INT(m->nverts, orig->nverts);
    expect_refused(m, NULL, PD_ERR_ORIENTATION, "does not bound a solid");
    expect_refused(m, NULL, PD_ERR_ORIENTATION, "principal moments of inertia from -");

    /* The shipped part builds and its own centre of mass is inside the
     * mutated part's hull (the spike only adds to the hull). */
    pd_part *good = NULL;
    CHECK_STATUS(pd_part_build(orig, NULL, &good, NULL), PD_OK);
    pd_part_options o;
    pd_part_options_default(&o);
    o.com_given = 1;
    if (good)
        o.com = v3_add(good->com, good->origin);
    pd_part_free(good);
    pd_diag d;
    pd_diag_init(&d);
    pd_part *p = NULL;
    pd_static_result *res = NULL;
    pd_sim_result *sim = NULL;
    pd_sim_options so;
    pd_sim_options_default(&so);
    so.ndrops = 2;
    so.threads = 1;
    CHECK_STATUS(pd_part_build(m, &o, &p, &d), PD_OK);
    CHECK(d.nwarnings >= 1);
    if (p) {
        CHECK_INT(p->mass_known, 0);
        CHECK_STATUS(pd_static_estimate(p, NULL, &res, NULL), PD_OK);
        if (res)
            CHECK_STATUS(pd_sim_run(p, res, NULL, &so, &sim, NULL), PD_OK);
    }
    pd_sim_result_free(sim);
    pd_static_result_free(res);
    pd_part_free(p);
    pd_mesh_free(m);
    pd_mesh_free(orig);
}

/* Two unit boxes, the second moved by dx, as one mesh of two shells. */
static pd_mesh *two_boxes(pd_vec3 dx)
{
    pd_mesh *a = mesh_box(1, 1, 1), *b = mesh_box(1, 1, 1), *m = calloc(1, sizeof *m);
    CHECK(a && b && m);
    if (!a || !b || !m) {
        pd_mesh_free(a);
        pd_mesh_free(b);
        free(m);
        return NULL;
    }
    m->nverts = a->nverts + b->nverts;
    m->ntris = a->ntris + b->ntris;
    m->verts = malloc(sizeof *m->verts * (size_t)m->nverts);
    m->tris = malloc(sizeof *m->tris * (size_t)m->ntris);
    for (int i = 0; i < a->nverts; i++)
        m->verts[i] = a->verts[i];
    for (int i = 0; i < b->nverts; i++)
        m->verts[a->nverts + i] = v3_add(b->verts[i], dx);
    for (int t = 0; t < a->ntris; t++)
        for (int c = 0; c < 3; c++)
            m->tris[t][c] = a->tris[t][c];
    for (int t = 0; t < b->ntris; t++)
        for (int c = 0; c < 3; c++)
            m->tris[a->ntris + t][c] = b->tris[t][c] + a->nverts;
    pd_mesh_free(a);
    pd_mesh_free(b);
    return m;
}

/* Two boxes that overlap: each shell is closed, so orientation cannot see
 * it. Nesting is judged at one point of each shell: where the second's
 * point lies inside the first, it is taken as a void and the volumes cancel;
 * where it does not, both count and the overlap counts twice, more than the
 * convex hull holds. Either way the mass properties are no solid's. */
static void test_overlapping_shells(void)
{
    pd_mesh *m = two_boxes(v3(0.5, 0, 0));
    expect_refused(m, NULL, PD_ERR_ORIENTATION, "encloses no volume, though its convex hull");
    pd_mesh_free(m);
    m = two_boxes(v3(0.7, 0, 0));
    expect_refused(m, NULL, PD_ERR_ORIENTATION, "more than its convex hull");
    pd_mesh_free(m);
    /* Apart, the same two boxes are one part of two shells. */
    m = two_boxes(v3(2.0, 0, 0));
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    if (p)
        CHECK_REL(p->mass.volume, 2.0, 1e-12, "two unit boxes, closed form");
    pd_part_free(p);
    pd_mesh_free(m);
}

/* The crossing point a refusal names, from its message; NaN when absent. */
static pd_vec3 crossing_point(const char *msg)
{
    const char *at = strstr(msg, "cross at (");
    pd_vec3 c = v3(NAN, NAN, NAN);
    if (at && sscanf(at, "cross at (%lf, %lf, %lf)", &c.x, &c.y, &c.z) != 3)
        c = v3(NAN, NAN, NAN);
    return c;
}

/* Two unit boxes offset by 0.7 along each axis: the overlap (0.3^3) counts
 * twice, but the volume (2 m^3) and moments stay within the hull's, so only
 * a test of the surface against itself sees it. The crossing lies on the
 * boundary of the common box [0.2, 0.5]^3 (box centred at the origin), and
 * so does the point named, once the placement is undone, wherever the pair
 * is moved, turned and scaled (1e-3 to 1e3): the decision is exact, the
 * point is printed with 9 significant digits of coordinates up to 6.2 box
 * edges from the origin (moved by 5 edges), 3.1e-8 of an edge at most, so
 * it is checked to 1e-7 of the edge.
 * With a given centre of mass the part is built with a warning and without
 * the mesh's mass properties. */
static void test_surface_crosses_itself(void)
{
    test_rng rng = {2026112722};
    const double scales[] = {1.0, 1e-3, 1e3, 0.37};
    for (int k = 0; k < 4; k++) {
        pd_mesh *m = two_boxes(v3(0.7, 0.7, 0.7));
        if (!m)
            return;
        double R[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        pd_vec3 t = v3(0, 0, 0);
        if (k > 0) {
            rng_rotation(&rng, R);
            t = v3_scale(rng_unit_vector(&rng), 5.0 * scales[k]);
            mesh_transform(m, CR(R), scales[k], t);
        }
        expect_refused(m, NULL, PD_ERR_ORIENTATION, "its surface passes through itself (triangles");
        pd_diag d;
        pd_diag_init(&d);
        pd_part *p = NULL;
        pd_part_build(m, NULL, &p, &d);
        pd_vec3 c = v3_sub(crossing_point(d.message), t), u;
        /* Undo x -> s R x + t: u = R^T (x - t) / s. */
        u.x = (R[0][0] * c.x + R[1][0] * c.y + R[2][0] * c.z) / scales[k];
        u.y = (R[0][1] * c.x + R[1][1] * c.y + R[2][1] * c.z) / scales[k];
        u.z = (R[0][2] * c.x + R[1][2] * c.y + R[2][2] * c.z) / scales[k];
        double e = 1e-7, lo = fmin(fmin(u.x, u.y), u.z), hi = fmax(fmax(u.x, u.y), u.z);
        if (!(lo >= 0.2 - e && hi <= 0.5 + e && (fabs(lo - 0.2) <= e || fabs(hi - 0.5) <= e)))
            printf("     scale %g: crossing named at %g, %g, %g (unplaced)\n", scales[k], u.x,
                   u.y, u.z);
        CHECK(lo >= 0.2 - e && hi <= 0.5 + e);
        CHECK(fabs(lo - 0.2) <= e || fabs(hi - 0.5) <= e);
        if (k == 0) {
            pd_part_options o;
            pd_part_options_default(&o);
            o.com_given = 1;
            o.com = v3(0.35, 0.35, 0.35);
            pd_diag_init(&d);
            CHECK_STATUS(pd_part_build(m, &o, &p, &d), PD_OK);
            CHECK_INT(d.nwarnings, 1);
            if (p)
                CHECK_INT(p->mass_known, 0);
            pd_part_free(p);
        }
        pd_mesh_free(m);
    }
}

/* Touching is not crossing: a tetrahedron whose corner rests on the inside
 * of another's face (two vertices at the same point, not welded: the point
 * lies within a face), and one that shares a corner with it, are parts
 * whose volume is the two tetrahedra's (1/6 each, closed form). A convex
 * hull of random points crosses nothing. */
static void test_touching_is_not_crossing(void)
{
    static const pd_vec3 apex[2][4] = {
        {{0.25, 0.25, 0.5}, {1, 1, 2}, {2, 1, 1}, {1, 2, 1}},
        {{1, 0, 0}, {2, 0, 0}, {2, 1, 0}, {2, 0, 1}},
    };
    for (int k = 0; k < 2; k++) {
        pd_mesh *m = calloc(1, sizeof *m);
        m->nverts = 8;
        m->verts = malloc(sizeof *m->verts * 8);
        m->ntris = 8;
        m->tris = malloc(sizeof *m->tris * 8);
        const pd_vec3 base[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        const int t[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
        for (int i = 0; i < 4; i++) {
            m->verts[i] = base[i];
            m->verts[4 + i] = apex[k][i];
            for (int c = 0; c < 3; c++) {
                m->tris[i][c] = t[i][c];
                m->tris[4 + i][c] = t[i][c] + 4;
            }
        }
        double v2 = fabs(v3_dot(v3_sub(apex[k][1], apex[k][0]),
                                v3_cross(v3_sub(apex[k][2], apex[k][0]),
                                         v3_sub(apex[k][3], apex[k][0])))) / 6.0;
        pd_diag d;
        pd_diag_init(&d);
        pd_part *p = NULL;
        CHECK_STATUS(pd_part_build(m, NULL, &p, &d), PD_OK);
        if (!p)
            printf("     touching tetrahedra %d: %s\n", k, d.message);
        if (p)
            CHECK_REL(p->mass.volume, 1.0 / 6.0 + v2, 1e-12, "two tetrahedra, closed form");
        pd_part_free(p);
        pd_mesh_free(m);
    }
    test_rng rng = {99};
    pd_vec3 pts[60];
    for (int i = 0; i < 60; i++)
        pts[i] = v3_scale(rng_unit_vector(&rng), rng_range(&rng, 0.9, 1.0));
    pd_mesh *m = convex_mesh(pts, 60);
    pd_part *p = NULL;
    CHECK(m != NULL);
    if (m)
        CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    if (p)
        CHECK_INT(p->mass_known, 1);
    pd_part_free(p);
    pd_mesh_free(m);
}

/* The checks of a solid refuse none of the shipped parts, printed with 6 to
 * 9 digits, binary STL and OBJ among them: their tolerances sit above the
 * files' noise. */
static void test_shipped_parts_are_solids(void)
{
    static const char *const parts[] = {
        "parts/block.stl", "parts/button.off", "parts/cap.off", "parts/hexnut.obj",
        "parts/insulator_cap.off", "parts/rect_black_button.off",
        "parts/square_black_button.off", "parts/white_button.off",
        "parts/canonical/box_1x2x3.off", "parts/canonical/coin_h0.1.off",
        "parts/canonical/l_bracket.off", "parts/canonical/loaded_die.off",
        "parts/canonical/platonic_tetrahedron.off", "parts/canonical/tile_10x8x0.5.off",
    };
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
        pd_mesh_read_options ro;
        pd_mesh_read_options_default(&ro);
        if (strstr(parts[i], "hexnut"))
            ro.units = PD_UNITS_MM;
        pd_mesh *m = NULL;
        pd_part *p = NULL;
        pd_diag d;
        pd_diag_init(&d);
        pd_status st = pd_mesh_read(parts[i], &ro, &m, &d);
        if (st == PD_OK)
            st = pd_part_build(m, NULL, &p, &d);
        if (st != PD_OK)
            printf("     %s: %s\n", parts[i], d.message);
        CHECK_STATUS(st, PD_OK);
        CHECK(p && p->mass_known);
        pd_part_free(p);
        pd_mesh_free(m);
    }
}

/* A rod of square section r x r and length 1: its smallest principal
 * moment is r^2 / 6 / ((1 + r^2) / 12) ~ 2 r^2 of its largest (closed
 * form). At r = 3e-6 (1.8e-11, below PD_TOL_INERTIA_REL) it is refused
 * as too thin, whatever is asked of it; at r = 1e-4 (2e-8) it is a part. */
static pd_mesh *rod(double r)
{
    /* Corner k at (x, y, z) = bits 0, 1, 2 of k; two outward triangles per
     * face. */
    static const int tris[12][3] = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                    {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                    {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    pd_mesh *m = calloc(1, sizeof *m);
    m->nverts = 8;
    m->ntris = 12;
    m->verts = malloc(sizeof *m->verts * 8);
    m->tris = malloc(sizeof tris);
    for (int k = 0; k < 8; k++)
        m->verts[k] = v3(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 * r : -0.5 * r, k & 4 ? 0.5 * r : -0.5 * r);
    memcpy(m->tris, tris, sizeof tris);
    return m;
}

static void test_thin_rod(void)
{
    pd_mesh *m = rod(3e-6);
    expect_refused(m, NULL, PD_ERR_COLLINEAR, "too thin");
    pd_mesh_free(m);
    m = rod(1e-4);
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &p, NULL), PD_OK);
    pd_part_free(p);
    pd_mesh_free(m);
}

/* The static pipeline stopped by its cancel flag: a flag already set
 * makes reading (a text of more lines than the reader reads between two
 * looks at the flag, and one of fewer), the part build, the self-crossing
 * check and the static estimate each return PD_ERR_CANCELLED, with nothing
 * made; a flag present but clear changes no result (the same poses, bit for
 * bit, as without one). */
static void test_cancel(void)
{
    pd_cancel_flag set, clear;
    atomic_init(&set, 2);
    atomic_init(&clear, 0);
    /* The hull of 5000 random points on a sphere: over 4096 lines, and
     * over 4096 vertices. */
    enum { NP = 5000 };
    pd_vec3 *pts = malloc(sizeof *pts * NP);
    test_rng rng = {20261207};
    for (int i = 0; pts && i < NP; i++)
        pts[i] = rng_unit_vector(&rng);
    pd_hull *h = NULL;
    pd_mesh *m = pts && pd_hull_build(pts, NP, &h, NULL) == PD_OK ? mesh_of_hull(h) : NULL;
    pd_hull_free(h);
    free(pts);
    if (!m)
        return;
    size_t size = 64 + 80 * ((size_t)m->nverts + (size_t)m->ntris), len = 0;
    char *off = malloc(size);
    if (!off) {
        pd_mesh_free(m);
        return;
    }
    len += (size_t)snprintf(off + len, size - len, "OFF\n%d %d 0\n", m->nverts, m->ntris);
    for (int i = 0; i < m->nverts; i++)
        len += (size_t)snprintf(off + len, size - len, "%.17g %.17g %.17g\n", m->verts[i].x,
                                m->verts[i].y, m->verts[i].z);
    for (int t = 0; t < m->ntris; t++)
        len += (size_t)snprintf(off + len, size - len, "3 %d %d %d\n", m->tris[t][0],
                                m->tris[t][1], m->tris[t][2]);
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    CHECK(ro.cancel == NULL);
    pd_diag d;
    const char *tiny = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    const char *texts[2] = {off, tiny};
    size_t sizes[2] = {len, strlen(tiny)};
    for (int k = 0; k < 2; k++) {
        pd_mesh *got = NULL;
        ro.cancel = &set;
        pd_diag_init(&d);
        CHECK_STATUS(pd_mesh_parse(texts[k], sizes[k], "c.off", &ro, &got, &d), PD_ERR_CANCELLED);
        CHECK(got == NULL);
        CHECK(strstr(d.message, "c.off") != NULL);
        ro.cancel = &clear;
        CHECK_STATUS(pd_mesh_parse(texts[k], sizes[k], "c.off", &ro, &got, &d), PD_OK);
        pd_mesh_free(got);
    }
    free(off);

    pd_part_options po;
    pd_part_options_default(&po);
    CHECK(po.cancel == NULL && po.stage == NULL);
    pd_part *p = NULL;
    po.cancel = &set;
    pd_diag_init(&d);
    CHECK_STATUS(pd_part_build(m, &po, &p, &d), PD_ERR_CANCELLED);
    CHECK(p == NULL);
    /* Weld, orientation and the hull read the flag inside their loops
     * (over 4,096 vertices and triangles here, the steps between reads):
     * set, each returns PD_ERR_CANCELLED and leaves the mesh as it was;
     * clear, each does what it does without a flag. */
    {
        pd_mesh *w = pd_mesh_clone(m), *w0 = pd_mesh_clone(m);
        if (w && w0) {
            double tol = PD_TOL_WELD_REL * pd_mesh_size(m);
            CHECK(m->nverts > 4096);
            CHECK_STATUS(pd_mesh_weld_cancel(w, tol, NULL, &set), PD_ERR_CANCELLED);
            CHECK(w->nverts == m->nverts && w->ntris == m->ntris &&
                  memcmp(w->tris, m->tris, sizeof *m->tris * (size_t)m->ntris) == 0);
            int n1 = -1, n0 = -2;
            CHECK_STATUS(pd_mesh_weld_cancel(w, tol, &n1, &clear), PD_OK);
            CHECK_STATUS(pd_mesh_weld(w0, tol, &n0), PD_OK);
            CHECK_INT(n1, n0);
            /* Turned over, so that orientation has triangles to flip. */
            for (int t = 0; t < w->ntris; t++) {
                int x = w->tris[t][1];
                w->tris[t][1] = w->tris[t][2];
                w->tris[t][2] = x;
            }
            int f1 = -1, f0 = -2;
            pd_diag_init(&d);
            CHECK_STATUS(pd_mesh_orient_cancel(w, &f1, &set, &d), PD_ERR_CANCELLED);
            CHECK(f1 == -1 && w->tris[0][1] != w0->tris[0][1]);
            CHECK_STATUS(pd_mesh_orient_cancel(w, &f1, &clear, &d), PD_OK);
            CHECK_INT(f1, w->ntris);
            CHECK_STATUS(pd_mesh_orient(w0, &f0, &d), PD_OK);
            CHECK_INT(f0, 0);
            pd_hull *hs = NULL, *hc = NULL, *h0 = NULL;
            CHECK_STATUS(pd_hull_build_cancel(w->verts, w->nverts, &set, &hs, &d), PD_ERR_CANCELLED);
            CHECK(hs == NULL);
            CHECK_STATUS(pd_hull_build_cancel(w->verts, w->nverts, &clear, &hc, &d), PD_OK);
            CHECK_STATUS(pd_hull_build(w->verts, w->nverts, &h0, &d), PD_OK);
            CHECK(hc && h0 && hc->nfacets == h0->nfacets && hc->nverts == h0->nverts);
            pd_hull_free(hc);
            pd_hull_free(h0);
        }
        pd_mesh_free(w);
        pd_mesh_free(w0);
    }
    /* Cancelled at the check itself, the stages before it run. */
    int ta, tb;
    pd_vec3 at;
    CHECK_STATUS(pd_mesh_self_crossing(m, &set, &ta, &tb, &at, NULL), PD_ERR_CANCELLED);
    CHECK_STATUS(pd_mesh_self_crossing(m, &clear, &ta, &tb, &at, NULL), PD_OK);
    CHECK_INT(ta, -1);

    po.cancel = &clear;
    pd_part *p1 = NULL, *p2 = NULL;
    CHECK_STATUS(pd_part_build(m, &po, &p1, &d), PD_OK);
    CHECK_STATUS(pd_part_build(m, NULL, &p2, &d), PD_OK);
    if (p1 && p2) {
        pd_static_options so;
        pd_static_options_default(&so);
        CHECK(so.cancel == NULL);
        pd_static_result *r1 = NULL, *r2 = NULL;
        so.cancel = &set;
        CHECK_STATUS(pd_static_estimate(p1, &so, &r1, &d), PD_ERR_CANCELLED);
        CHECK(r1 == NULL);
        so.cancel = &clear;
        CHECK_STATUS(pd_static_estimate(p1, &so, &r1, &d), PD_OK);
        CHECK_STATUS(pd_static_estimate(p2, NULL, &r2, &d), PD_OK);
        if (r1 && r2) {
            CHECK_INT(r1->nposes, r2->nposes);
            for (int i = 0; i < r1->nposes && i < r2->nposes; i++)
                CHECK(r1->poses[i].p_qs == r2->poses[i].p_qs &&
                      r1->poses[i].p_pqs == r2->poses[i].p_pqs);
        }
        pd_static_result_free(r1);
        pd_static_result_free(r2);
    }
    pd_part_free(p1);
    pd_part_free(p2);
    pd_mesh_free(m);
}

/* The build's stages named, in order, to a stage callback. */
static void note_stage(void *user, const char *name)
{
    char *seen = user;
    size_t n = strlen(seen);
    snprintf(seen + n, 256 - n, "%s;", name);
}

/* pd_part_build_take: the same part as pd_part_build, the mesh taken (the
 * caller's pointer NULL) on success and on failure alike. */
static void test_take(void)
{
    pd_mesh *m = mesh_roof_box(0.03, 0.02, 0.01, 0.004), *copy = pd_mesh_clone(m);
    pd_part *a = NULL, *b = NULL;
    CHECK_STATUS(pd_part_build(m, NULL, &a, NULL), PD_OK);
    CHECK_STATUS(pd_part_build_take(&copy, NULL, &b, NULL), PD_OK);
    CHECK(copy == NULL);
    if (a && b) {
        /* Bit for bit: the same stages on the same numbers. */
        CHECK(a->mass.volume == b->mass.volume && a->com.x == b->com.x && a->com.z == b->com.z &&
              a->hull->nfacets == b->hull->nfacets && a->mesh->ntris == b->mesh->ntris);
    }
    pd_part_free(a);
    pd_part_free(b);
    b = NULL;
    /* Refused (an open mesh without a given centre of mass): taken too. */
    copy = pd_mesh_clone(m);
    if (copy)
        copy->ntris--;
    pd_diag d;
    pd_diag_init(&d);
    CHECK(pd_part_build_take(&copy, NULL, &b, &d) != PD_OK);
    CHECK(copy == NULL && b == NULL);
    pd_mesh_free(m);
}

static void test_stages(void)
{
    pd_mesh *m = mesh_box(1, 2, 3);
    if (!m)
        return;
    char seen[256] = "";
    pd_part_options po;
    pd_part_options_default(&po);
    po.stage = note_stage;
    po.stage_user = seen;
    pd_part *p = NULL;
    CHECK_STATUS(pd_part_build(m, &po, &p, NULL), PD_OK);
    CHECK(strcmp(seen, "welding;convex hull;orienting;mass properties;self-crossing check;") == 0);
    pd_part_free(p);
    pd_mesh_free(m);
}

void suite_part(void)
{
    test_cancel();
    test_take();
    test_stages();
    test_thin_rod();
    test_shipped_parts_are_solids();
    test_folded_through();
    test_overlapping_shells();
    test_surface_crosses_itself();
    test_touching_is_not_crossing();
    test_box();
    test_refusals();
    test_orientation();
}
