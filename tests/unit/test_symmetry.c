/* test_symmetry.c: rotation groups of hulls about their centre of mass and
 * the pose classes they induce, against the known groups of the standard
 * solids; mirror images kept apart; a moved centre of mass breaking the
 * symmetry; invariance under rigid motions and scale; the generated search
 * against the exhaustive one, rotation for rotation, on exact, noisy and
 * rounded hulls; bodies of revolution of thousands of vertices. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "posedrop/tolerances.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "base/stats.h"
#include "suites.h"
#include "symmetry/symmetry_orbit.h"
#include "symmetry/symmetry_search.h"
#include "base/vec3.h"

/* Every rotation found is orthonormal with determinant +1 (round-off of a
 * product of two orthonormal frames: a few 1e-16 per entry; 1e-12 leaves a
 * wide margin), the first is the identity, and each sends every hull vertex
 * onto a hull vertex. Returns the group's order, -1 on failure. */
static int group_order(const pd_part *part)
{
    pd_symmetry *s = NULL;
    if (pd_symmetry_find(part, &s, NULL) != PD_OK) {
        CHECK(!"pd_symmetry_find failed");
        return -1;
    }
    int ok_orth = 1, ok_map = 1, ok_id = 1;
    const pd_hull *h = part->hull;
    double tol = PD_TOL_SYMMETRY_REL * part->size;
    for (int g = 0; g < s->nrotations; g++) {
        const double(*R)[3] = CR(s->rotation[g]);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double d = R[0][i] * R[0][j] + R[1][i] * R[1][j] + R[2][i] * R[2][j];
                ok_orth &= fabs(d - (i == j)) < 1e-12;
                if (g == 0)
                    ok_id &= R[i][j] == (double)(i == j);
            }
        double det = R[0][0] * (R[1][1] * R[2][2] - R[1][2] * R[2][1]) -
                     R[0][1] * (R[1][0] * R[2][2] - R[1][2] * R[2][0]) +
                     R[0][2] * (R[1][0] * R[2][1] - R[1][1] * R[2][0]);
        ok_orth &= fabs(det - 1.0) < 1e-12;
        for (int v = 0; v < h->nverts && ok_map; v++) {
            pd_vec3 x = v3_add(rot_apply(R, v3_sub(h->verts[v], part->com)), part->com);
            double best = INFINITY;
            for (int u = 0; u < h->nverts; u++)
                best = fmin(best, v3_dist(x, h->verts[u]));
            ok_map &= best <= tol;
        }
    }
    CHECK(ok_orth);
    CHECK(ok_id);
    CHECK(ok_map);
    int n = s->nrotations;
    CHECK_INT(s->capped, 0);
    pd_symmetry_free(s);
    return n;
}

typedef struct {
    pd_static_result *res;
    int *class_of;
    int nclasses;
    int size[256];  /* members per class (first 256 classes) */
} grouping;

static void grouping_free(grouping *g)
{
    pd_static_result_free(g->res);
    free(g->class_of);
    memset(g, 0, sizeof *g);
}

/* Static estimate and classes of a part; checks that class numbers run from
 * 0 in order of first appearance and that the members of a class have the
 * same QS and PQS probabilities. Why 1e-9 relative: symmetric facets' solid
 * angles are sums of the same triangles' in another order and another frame,
 * equal to round-off (~1e-15); PQS transfers are decided on them with the tie
 * tolerance, so a class must not be split by a transfer either. Plus 1e-15
 * absolute: a probability that is 0 exactly (everything handed on) comes out
 * as the round-off of a difference of terms of order 1, a few 1e-18. */
static int group(const pd_part *part, grouping *g)
{
    memset(g, 0, sizeof *g);
    if (!part || pd_static_estimate(part, NULL, &g->res, NULL) != PD_OK) {
        CHECK(!"static estimate failed");
        return 0;
    }
    g->class_of = malloc(sizeof *g->class_of * (size_t)(g->res->nposes + 1));
    CHECK_STATUS(pd_pose_classes(part, g->res, g->class_of, &g->nclasses, NULL), PD_OK);
    int in_range = 1, agree = 1;
    double qs[256] = {0};
    for (int i = 0; i < g->res->nposes; i++) {
        int c = g->class_of[i];
        in_range &= c >= 0 && c < g->nclasses;
        if (c >= 0 && c < 256) {
            g->size[c]++;
            qs[c] += g->res->poses[i].p_qs;
        }
        int first = 0;
        while (g->class_of[first] != c)
            first++;
        const pd_pose *p = &g->res->poses[i], *q = &g->res->poses[first];
        agree &= fabs(p->p_qs - q->p_qs) <= 1e-9 * q->p_qs + 1e-15;
        agree &= fabs(p->p_pqs - q->p_pqs) <= 1e-9 * q->p_pqs + 1e-15;
        agree &= fabs(p->height - q->height) <= 1e-9 * q->height;
        agree &= fabs(p->area - q->area) <= 1e-9 * q->area;
    }
    /* Every class has members, numbered most probable (summed QS) first,
     * as the poses are; sums within the tie tolerance (round-off) may come
     * in either order. */
    int used = 1, order_ok = 1;
    for (int c = 0; c < g->nclasses && c < 256; c++) {
        used &= g->size[c] > 0;
        if (c > 0)
            order_ok &= qs[c] - qs[c - 1] <= PD_TOL_PROB_TIE_REL * qs[c];
    }
    CHECK(in_range && used);
    CHECK(order_ok);
    CHECK(agree);
    return 1;
}

/* A solid whose poses all form one class. */
static void check_transitive(const char *name, pd_vec3 *pts, int n, int order, int nposes)
{
    pd_part *part = part_of(convex_mesh(pts, n), NULL, NULL);
    grouping g;
    int got = group_order(part);
    if (got != order)
        printf("     %s\n", name);
    CHECK_INT(got, order);
    if (group(part, &g)) {
        CHECK_INT(g.res->nposes, nposes);
        CHECK_INT(g.nclasses, 1);
    }
    grouping_free(&g);
    pd_part_free(part);
}

static void test_platonic(void)
{
    pd_vec3 p[64];
    check_transitive("cube", p, pts_cube(p), 24, 6);
    check_transitive("tetrahedron", p, pts_tetrahedron(p), 12, 4);
    check_transitive("octahedron", p, pts_octahedron(p), 24, 8);
    check_transitive("icosahedron", p, pts_icosahedron(p), 60, 20);
    check_transitive("dodecahedron", p, pts_dodecahedron(p), 60, 12);
}

static void test_box(void)
{
    /* 1 x 2 x 3: the three half turns about the axes and the identity; each
     * pair of opposite faces is one class. */
    pd_part *part = part_of(mesh_box(1, 2, 3), NULL, NULL);
    CHECK_INT(group_order(part), 4);
    grouping g;
    if (group(part, &g)) {
        CHECK_INT(g.res->nposes, 6);
        CHECK_INT(g.nclasses, 3);
        for (int c = 0; c < 3; c++)
            CHECK_INT(g.size[c], 2);
        /* Opposite normals in each class. */
        int opposite = 1;
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++)
                if (i != j && g.class_of[i] == g.class_of[j])
                    opposite &= v3_dot(g.res->poses[i].normal, g.res->poses[j].normal) < -0.999;
        CHECK(opposite);
    }
    grouping_free(&g);
    pd_part_free(part);
}

static void test_prisms(void)
{
    /* Regular n-gon prisms: the dihedral group D_n, 2n rotations; the caps
     * are one class, the n sides another. */
    const int ns[] = {5, 6, 32};
    for (int k = 0; k < 3; k++) {
        int n = ns[k];
        pd_part *part = part_of(mesh_prism(n, 1.0, 1.3), NULL, NULL);
        CHECK_INT(group_order(part), 2 * n);
        grouping g;
        if (group(part, &g)) {
            CHECK_INT(g.res->nposes, n + 2);
            CHECK_INT(g.nclasses, 2);
            int small = g.size[0] < g.size[1] ? 0 : 1;
            CHECK_INT(g.size[small], 2);
            CHECK_INT(g.size[1 - small], n);
            int caps_ok = 1;
            for (int i = 0; i < g.res->nposes; i++)
                caps_ok &= (g.class_of[i] == small) == (fabs(g.res->poses[i].normal.z) > 0.999);
            CHECK(caps_ok);
        }
        grouping_free(&g);
        pd_part_free(part);
    }
}

/* A 1 x 2 x 3 box with a small pyramid on its +x face, off centre in y only:
 * no rotation but the identity maps it onto itself, while the plane z = 0 is
 * still a mirror plane. The poses on +z and -z are mirror images of each
 * other, with equal probabilities, and must stay two classes. */
static void test_mirror(void)
{
    pd_vec3 p[16];
    int n = pts_box(1, 2, 3, p);
    p[n++] = v3(0.55, 0.4, 0.0);
    pd_part *part = part_of(convex_mesh(p, n), NULL, NULL);
    CHECK_INT(group_order(part), 1);
    grouping g;
    if (group(part, &g)) {
        CHECK_INT(g.nclasses, g.res->nposes);
        int up = -1, down = -1;
        for (int i = 0; i < g.res->nposes; i++) {
            if (g.res->poses[i].normal.z > 0.999)
                up = i;
            if (g.res->poses[i].normal.z < -0.999)
                down = i;
        }
        CHECK(up >= 0 && down >= 0);
        if (up >= 0 && down >= 0) {
            CHECK(g.class_of[up] != g.class_of[down]);
            CHECK_REL(g.res->poses[up].p_qs, g.res->poses[down].p_qs, 1e-9,
                      "mirror images: same solid angles");
        }
    }
    grouping_free(&g);
    pd_part_free(part);

    /* A chiral part with a non-trivial group: a hexagonal prism whose top is
     * turned by 17 degrees against its bottom. The half turns about the
     * horizontal axes survive (D_6, 12 rotations), the mirror planes do not;
     * its mirror image is a different part, and it has the same group. */
    for (int mirror = 0; mirror < 2; mirror++) {
        pd_vec3 q[12];
        for (int i = 0; i < 6; i++) {
            double t = 2.0 * M_PI * i / 6, u = t + 17.0 * M_PI / 180.0;
            double sx = mirror ? -1.0 : 1.0;
            q[i] = v3(sx * cos(t), sin(t), -0.6);
            q[6 + i] = v3(sx * cos(u), sin(u), 0.6);
        }
        part = part_of(convex_mesh(q, 12), NULL, NULL);
        CHECK_INT(group_order(part), 12);
        if (group(part, &g)) {
            /* Two caps, swapped by the half turns, and 12 side triangles:
             * those with their base at the bottom and those with it at the
             * top are swapped by the half turns too, so all 12 are one class. */
            CHECK_INT(g.res->nposes, 14);
            CHECK_INT(g.nclasses, 2);
            CHECK_INT(g.size[0] + g.size[1], 14);
            CHECK(g.size[0] == 2 || g.size[1] == 2);
        }
        grouping_free(&g);
        pd_part_free(part);
    }
}

/* A centre of mass off the box's centre keeps only the rotations that fix it. */
static void test_offset_com(void)
{
    /* On the x axis: the half turn about x stays; +-x stay apart, +-y and
     * +-z remain pairs. */
    pd_vec3 com = v3(0.1, 0.0, 0.0);
    pd_part *part = part_of(mesh_box(1, 2, 3), &com, NULL);
    CHECK_INT(group_order(part), 2);
    grouping g;
    if (group(part, &g)) {
        CHECK_INT(g.res->nposes, 6);
        CHECK_INT(g.nclasses, 4);
        int px = -1, mx = -1;
        for (int i = 0; i < 6; i++) {
            if (g.res->poses[i].normal.x > 0.999)
                px = i;
            if (g.res->poses[i].normal.x < -0.999)
                mx = i;
        }
        CHECK(px >= 0 && mx >= 0 && g.class_of[px] != g.class_of[mx]);
    }
    grouping_free(&g);
    pd_part_free(part);

    /* Off every axis: nothing but the identity; six classes. */
    com = v3(0.1, 0.2, 0.0);
    part = part_of(mesh_box(1, 2, 3), &com, NULL);
    CHECK_INT(group_order(part), 1);
    if (group(part, &g))
        CHECK_INT(g.nclasses, 6);
    grouping_free(&g);
    pd_part_free(part);

    /* A prism's centre moved along its axis: the half turns swapping the caps
     * go, the n turns about the axis stay; caps split, sides stay one. */
    com = v3(0.0, 0.0, 0.1);
    part = part_of(mesh_prism(6, 1.0, 1.3), &com, NULL);
    CHECK_INT(group_order(part), 6);
    if (group(part, &g))
        CHECK_INT(g.nclasses, 3);
    grouping_free(&g);
    pd_part_free(part);
}

/* Class sizes and class probabilities, sorted: what must not change when the
 * part is moved or scaled (the pose order may, as ties go by normal). */
typedef struct {
    int size;
    double p;
} class_sig;

static int by_sig(const void *a, const void *b)
{
    const class_sig *x = a, *y = b;
    if (x->size != y->size)
        return x->size - y->size;
    return (x->p > y->p) - (x->p < y->p);
}

static int signature(const grouping *g, class_sig *sig, int max)
{
    int n = g->nclasses < max ? g->nclasses : max;
    for (int c = 0; c < n; c++) {
        sig[c].size = 0;
        sig[c].p = 0.0;
    }
    for (int i = 0; i < g->res->nposes; i++)
        if (g->class_of[i] < n) {
            sig[g->class_of[i]].size++;
            sig[g->class_of[i]].p += g->res->poses[i].p_qs;
        }
    qsort(sig, (size_t)n, sizeof *sig, by_sig);
    return n;
}

/* The classes of a moved part (g1) against the reference's signature. */
static void check_same_classes(const grouping *g1, const class_sig *s0, int n0)
{
    class_sig s1[64];
    int n1 = signature(g1, s1, 64);
    CHECK_INT(n1, n0);
    int same = n1 == n0;
    for (int c = 0; c < n0 && same; c++)
        same = s0[c].size == s1[c].size && fabs(s0[c].p - s1[c].p) <= 1e-9;
    CHECK(same);
}

static void test_invariance(void)
{
    test_rng rng = {12345};
    pd_vec3 p[64];
    for (int shape = 0; shape < 4; shape++) {
        int n;
        switch (shape) {
        case 0: n = pts_box(1, 2, 3, p); break;
        case 1: n = pts_prism(6, 1.0, 1.3, p); break;
        case 2: n = pts_icosahedron(p); break;
        default:
            n = pts_box(1, 2, 3, p);
            p[n++] = v3(0.55, 0.4, 0.0);
            break;
        }
        pd_part *ref = part_of(convex_mesh(p, n), NULL, NULL);
        int order = group_order(ref);
        grouping g0;
        class_sig s0[64];
        int n0 = group(ref, &g0) ? signature(&g0, s0, 64) : 0;
        const double scales[] = {1e-3, 1.0, 1e3};
        for (int s = 0; s < 3; s++) {
            double R[3][3];
            rng_rotation(&rng, R);
            pd_vec3 t = v3_scale(rng_unit_vector(&rng), 10.0 * scales[s]);
            pd_vec3 q[64];
            memcpy(q, p, sizeof *p * (size_t)n);
            points_transform(q, n, CR(R), scales[s], t);
            pd_part *part = part_of(convex_mesh(q, n), NULL, NULL);
            CHECK_INT(group_order(part), order);
            grouping g1;
            if (group(part, &g1))
                check_same_classes(&g1, s0, n0);
            grouping_free(&g1);
            pd_part_free(part);
        }
        grouping_free(&g0);
        pd_part_free(ref);
    }
}

static pd_part *big_prism(int n)
{
    ring_spec r = {n, 0, 0.0, 0.0, 0.0, 0, 0};
    return ring_part(&r, NULL, 1.0, v3(0, 0, 0));
}

static void test_large(void)
{
    /* A 400-gon: 800 rotations, found among 800 x 800 candidate pairs. */
    pd_part *part = big_prism(400);
    pd_symmetry *s = NULL;
    CHECK(part != NULL);
    if (part && pd_symmetry_find(part, &s, NULL) == PD_OK) {
        CHECK_INT(s->nrotations, 800);
        CHECK_INT(s->capped, 0);
    }
    pd_symmetry_free(s);
    grouping g;
    if (part && group(part, &g))
        CHECK_INT(g.nclasses, 2);
    grouping_free(&g);
    pd_part_free(part);

    /* Past PD_SYMMETRY_MAX_PAIRS (all 10^4 vertices at one distance from the
     * centre: 10^8 pairs): identity only, a warning, and every pose its own
     * class. */
    pd_diag diag;
    pd_diag_init(&diag);
    part = big_prism(5000);
    s = NULL;
    CHECK(part != NULL);
    if (part && pd_symmetry_find(part, &s, &diag) == PD_OK) {
        CHECK_INT(s->nrotations, 1);
        CHECK_INT(s->capped, 1);
        CHECK_INT(diag.nwarnings, 1);
    }
    pd_symmetry_free(s);
    pd_part_free(part);
}

/* The generated search against the exhaustive one (the search before it,
 * kept for this): the same rotations, bit for bit and in the same order,
 * and the same classes. Returns 1 if they agree. */
static int methods_agree(const pd_part *part, const char *name)
{
    pd_symmetry *gen = NULL, *exh = NULL;
    pd_static_result *res = NULL;
    int ok = part && pd_symmetry_find_by(part, PD_SYMMETRY_GENERATED, &gen, NULL) == PD_OK &&
             pd_symmetry_find_by(part, PD_SYMMETRY_EXHAUSTIVE, &exh, NULL) == PD_OK &&
             pd_static_estimate(part, NULL, &res, NULL) == PD_OK;
    ok = ok && gen->nrotations == exh->nrotations && gen->capped == exh->capped &&
         memcmp(gen->rotation, exh->rotation, sizeof *gen->rotation * (size_t)gen->nrotations) == 0;
    if (ok) {
        int *c1 = malloc(sizeof *c1 * (size_t)(res->nposes + 1));
        int *c2 = malloc(sizeof *c2 * (size_t)(res->nposes + 1));
        int n1 = -1, n2 = -2;
        ok = pd_pose_classes_by(part, res, PD_SYMMETRY_GENERATED, c1, &n1, NULL) == PD_OK &&
             pd_pose_classes_by(part, res, PD_SYMMETRY_EXHAUSTIVE, c2, &n2, NULL) == PD_OK &&
             n1 == n2 && memcmp(c1, c2, sizeof *c1 * (size_t)res->nposes) == 0;
        free(c1);
        free(c2);
    }
    if (!ok)
        printf("     methods disagree (or failed) on %s: %d / %d rotations, static %s\n", name,
               gen ? gen->nrotations : -1, exh ? exh->nrotations : -1, res ? "ok" : "failed");
    pd_symmetry_free(gen);
    pd_symmetry_free(exh);
    pd_static_result_free(res);
    return ok;
}

static void test_methods_agree(void)
{

    pd_vec3 p[64];
    const struct {
        const char *name;
        int (*pts)(pd_vec3 *);
    } solids[] = {{"cube", pts_cube}, {"tetrahedron", pts_tetrahedron},
                  {"octahedron", pts_octahedron}, {"icosahedron", pts_icosahedron},
                  {"dodecahedron", pts_dodecahedron}};
    for (size_t i = 0; i < sizeof solids / sizeof solids[0]; i++) {
        pd_part *part = part_of(convex_mesh(p, solids[i].pts(p)), NULL, NULL);
        CHECK(methods_agree(part, solids[i].name));
        pd_part_free(part);
    }
    const pd_vec3 coms[] = {{0, 0, 0}, {0.1, 0, 0}, {0.1, 0.2, 0}};
    for (int i = 0; i < 3; i++) {
        pd_part *part = part_of(mesh_box(1, 2, 3), &coms[i], NULL);
        CHECK(methods_agree(part, "box"));
        pd_part_free(part);
    }
    /* Exact rings; a chiral one; noisy corners doubled 1.2-1.6 tolerances
     * apart, so that the nearest vertex is the only test of some pairs (the
     * lookup check in the generated search); noise from a tenth of the tolerance,
     * where the products' error bound no longer decides and each vertex's
     * distance is measured, to a tolerance, where the rotations found stop
     * being a group; coordinates as binary STL and as 6- and 7-digit text
     * give. Sizes up to 400 sides keep the exhaustive search quick. */
    const double tol_angle = PD_TOL_SYMMETRY_REL * 3.0; /* tol / radius, rad */
    const ring_spec rings[] = {
        {5, 0, 0.0, 0.0, 0.0, 0, 0},      {32, 0, 0.0, 0.0, 0.0, 0, 0},
        {400, 0, 0.0, 0.0, 0.0, 0, 0},    {7, 1, 0.0, 0.0, 0.0, 0, 0},
        {300, 1, 0.0, 0.0, 0.0, 0, 0},    {12, 0, 0.3, 0.0, 0.0, 0, 0},
        {6, 0, 0.0, 1.2 * tol_angle, 0.3, 0, 0},  {7, 0, 0.0, 1.6 * tol_angle, 0.6, 0, 0},
        {7, 0, 0.3, 1.2 * tol_angle, 0.3, 0, 0},
        {32, 0, 0.0, 0.0, 0.1, 0, 0},     {200, 0, 0.0, 0.0, 0.3, 0, 0},
        {200, 0, 0.0, 0.0, 0.6, 0, 0},    {200, 1, 0.0, 0.0, 0.6, 0, 0},
        {32, 0, 0.0, 0.0, 1.0, 0, 0},     {400, 0, 0.0, 0.0, 0.0, 0, 1},
        {300, 1, 0.0, 0.0, 0.0, 0, 1},    {300, 0, 0.0, 0.0, 0.0, 6, 0},
        {300, 0, 0.0, 0.0, 0.0, 7, 0},
    };
    for (size_t i = 0; i < sizeof rings / sizeof rings[0]; i++) {
        char name[96];
        snprintf(name, sizeof name, "%d-gon %s, pair %g, noise %g, digits %d, float %d",
                 rings[i].nsides, rings[i].pyramid ? "pyramid" : "prism", rings[i].pair,
                 rings[i].noise, rings[i].digits, rings[i].float32);
        pd_part *part = ring_part(&rings[i], NULL, 1.0, v3(0, 0, 0));
        CHECK(methods_agree(part, name));
        pd_part_free(part);
    }
}

/* Bodies of revolution of thousands of vertices, which the exhaustive search
 * took seconds over: a 4000-gon prism (8000 vertices) has the dihedral group
 * D_4000 of 8000 rotations, its 4000 sides one class and its two caps
 * another; a 2000-gon pyramid the cyclic group C_2000, its sides one class,
 * its base alone. The same prism with float coordinates (binary STL) too:
 * its sides differ by the rounding, 1e-7 of its size, far inside the
 * tolerance, but their areas by ~1e-3 relative, so their probabilities are
 * not compared here as in group(). */
static void test_revolution(void)
{
    const ring_spec shapes[] = {{4000, 0, 0.0, 0.0, 0.0, 0, 0}, {2000, 1, 0.0, 0.0, 0.0, 0, 0},
                                {4000, 0, 0.0, 0.0, 0.0, 0, 1}};
    for (int k = 0; k < 3; k++) {
        const ring_spec *r = &shapes[k];
        pd_part *part = ring_part(r, NULL, 1.0, v3(0, 0, 0));
        pd_symmetry *s = NULL;
        pd_static_result *res = NULL;
        CHECK(part != NULL);
        if (part && pd_symmetry_find(part, &s, NULL) == PD_OK) {
            CHECK_INT(s->nrotations, r->pyramid ? r->nsides : 2 * r->nsides);
            CHECK_INT(s->capped, 0);
        }
        pd_symmetry_free(s);
        if (part && pd_static_estimate(part, NULL, &res, NULL) == PD_OK) {
            int *class_of = malloc(sizeof *class_of * (size_t)res->nposes);
            int nclasses = 0, size[2] = {0, 0}, ends_ok = 1;
            CHECK_STATUS(pd_pose_classes(part, res, class_of, &nclasses, NULL), PD_OK);
            CHECK_INT(res->nposes, r->nsides + (r->pyramid ? 1 : 2));
            CHECK_INT(nclasses, 2);
            for (int i = 0; i < res->nposes && nclasses == 2; i++)
                size[class_of[i]]++;
            int sides = size[0] == r->nsides ? 0 : 1;
            CHECK_INT(size[sides], r->nsides);
            CHECK_INT(size[1 - sides], r->pyramid ? 1 : 2);
            for (int i = 0; i < res->nposes && nclasses == 2; i++)
                ends_ok &= (class_of[i] != sides) == (fabs(res->poses[i].normal.z) > 0.999);
            CHECK(ends_ok);
            free(class_of);
        } else {
            CHECK(!"static estimate failed");
        }
        pd_static_result_free(res);
        pd_part_free(part);
    }
}

/* Moving, turning and scaling a 500-gon prism and a 300-gon pyramid changes
 * neither their groups nor their classes (sizes and probabilities, which
 * are invariant to 1e-9 as in test_invariance). */
static void test_invariance_large(void)
{
    test_rng rng = {2024};
    const ring_spec shapes[] = {{500, 0, 0.0, 0.0, 0.0, 0, 0}, {300, 1, 0.0, 0.0, 0.0, 0, 0}};
    for (int k = 0; k < 2; k++) {
        pd_part *ref = ring_part(&shapes[k], NULL, 1.0, v3(0, 0, 0));
        pd_symmetry *s0 = NULL;
        grouping g0;
        class_sig s0sig[64];
        int n0 = 0;
        CHECK(ref && pd_symmetry_find(ref, &s0, NULL) == PD_OK);
        if (ref && group(ref, &g0))
            n0 = signature(&g0, s0sig, 64);
        const double scales[] = {1e-3, 1.0, 1e3};
        for (int i = 0; i < 3; i++) {
            double R[3][3];
            rng_rotation(&rng, R);
            pd_vec3 t = v3_scale(rng_unit_vector(&rng), 10.0 * scales[i]);
            pd_part *part = ring_part(&shapes[k], CR(R), scales[i], t);
            pd_symmetry *s1 = NULL;
            CHECK(part && pd_symmetry_find(part, &s1, NULL) == PD_OK);
            if (s0 && s1)
                CHECK_INT(s1->nrotations, s0->nrotations);
            grouping g1;
            if (part && group(part, &g1))
                check_same_classes(&g1, s0sig, n0);
            grouping_free(&g1);
            pd_symmetry_free(s1);
            pd_part_free(part);
        }
        if (ref)
            grouping_free(&g0);
        pd_symmetry_free(s0);
        pd_part_free(ref);
    }
}

static void test_grouped_counts(void)
{
    /* Counts add up over a class; the interval is the class's own Wilson
     * interval, not a sum of the members'. */
    long count[4] = {10, 30, 25, 35};
    double p[4] = {0}, lo[4] = {0}, hi[4] = {0};
    pd_sim_result sim;
    memset(&sim, 0, sizeof sim);
    sim.nposes = 4;
    sim.n = 103;
    sim.unsettled = 3;
    sim.partial = 1;
    sim.count = count;
    sim.p = p;
    sim.ci_lo = lo;
    sim.ci_hi = hi;
    int class_of[4] = {0, 1, 0, 1};
    pd_sim_result *g = NULL;
    CHECK_STATUS(pd_sim_result_grouped(&sim, class_of, 2, &g, NULL), PD_OK);
    if (g) {
        CHECK_INT(g->nposes, 2);
        CHECK_INT(g->n, 103);
        CHECK_INT(g->unsettled, 3);
        CHECK_INT(g->partial, 1);
        CHECK_INT(g->count[0], 35);
        CHECK_INT(g->count[1], 65);
        CHECK_NEAR(g->p[1], 65.0 / 103.0, 1e-15, "round-off");
        double l, h;
        pd_wilson(65, 103, PD_Z95, &l, &h);
        CHECK(g->ci_lo[1] == l && g->ci_hi[1] == h);
        CHECK(g->trials == NULL);
    }
    pd_sim_result_free(g);
    g = NULL;
    int bad[4] = {0, 1, 2, 1};
    CHECK_STATUS(pd_sim_result_grouped(&sim, bad, 2, &g, NULL), PD_ERR_USAGE);
    CHECK(g == NULL);
}

/* The orbit of the reference pair under the generated permutations: a
 * 40-cycle gives the cyclic group, 40 elements, each reached by a product
 * that maps (a, b) where it says; adding a transposition generates all
 * permutations, whose orbit on pairs (40 x 39) outgrows any rotation group
 * of 40 vertices (at most 2 x 40 or 60 elements): PD_ORBIT_TOO_LARGE, the
 * signal on which the search falls back to the exhaustive loop. */
static void test_orbit_limit(void)
{
    enum { NV = 40 };
    int cyc[NV], swap[NV];
    for (int i = 0; i < NV; i++) {
        cyc[i] = (i + 1) % NV;
        swap[i] = i;
    }
    swap[0] = 1;
    swap[1] = 0;
    pd_orbit g;
    CHECK_INT(pd_orbit_init(&g, NV, 0, 1), 1);
    CHECK_INT(pd_orbit_add_generator(&g, cyc, 0.0), 1);
    CHECK_INT(g.n, NV);
    int wrong = 0;
    for (int k = 0; k < NV; k++) {
        int e = pd_orbit_find(&g, k, (k + 1) % NV);
        if (e < 0) {
            wrong++;
            continue;
        }
        /* Replay the tree of products from the identity. */
        int x = 0, y = 1, path[NV + 1], len = 0;
        for (int i = e; g.e[i].parent >= 0; i = g.e[i].parent)
            path[len++] = g.e[i].gen;
        while (len-- > 0)
            x = g.perm[path[len]][x], y = g.perm[path[len]][y];
        wrong += x != k || y != (k + 1) % NV;
    }
    CHECK_INT(wrong, 0);
    CHECK_INT(pd_orbit_add_generator(&g, swap, 0.0), PD_ORBIT_TOO_LARGE);
    pd_orbit_free(&g);
}

void suite_symmetry(void)
{
    test_orbit_limit();
    test_platonic();
    test_box();
    test_prisms();
    test_mirror();
    test_offset_com();
    test_invariance();
    test_large();
    test_methods_agree();
    test_revolution();
    test_invariance_large();
    test_grouped_counts();
}
