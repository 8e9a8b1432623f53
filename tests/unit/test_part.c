/* test_part.c: building the part model: what is accepted, what is refused
 * and with which status, and that the model is placed where the mesh is. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"
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

void suite_part(void)
{
    test_box();
    test_refusals();
    test_orientation();
}
