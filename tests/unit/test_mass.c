/* test_mass.c: pd_mesh_orient and pd_mass_compute against closed forms.
 *
 * Expected values come from formulas derived independently of the library's
 * signed-tetrahedron sums: boxes and prisms by direct integration, Platonic
 * solids from the textbook isotropic inertias, composite solids (L shape,
 * voids, disjoint parts) by superposition with the parallel-axis theorem. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "base/fail.h"
#include "posedrop/mass.h"
#include "posedrop/mesh.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

/* The accuracy asked of exact mass properties: round-off of sums of a few
 * 1e5 terms, each accurate to a few ulps, stays near 1e-15; 1e-12 leaves
 * three orders of margin and is still far below anything physical. */
#define REL 1e-12
#define REL_SRC "round-off: 1e-12 relative (exact formula, double precision)"

/* --- helpers ------------------------------------------------------------------ */

static pd_mesh *mesh_new(int nverts, int ntris)
{
    pd_mesh *m = calloc(1, sizeof *m);
    m->nverts = nverts;
    m->ntris = ntris;
    m->verts = calloc((size_t)nverts + 1, sizeof *m->verts);
    m->tris = calloc((size_t)ntris + 1, sizeof *m->tris);
    return m;
}

/* a followed by b (b's indices shifted); both are kept. */
static pd_mesh *mesh_concat(const pd_mesh *a, const pd_mesh *b)
{
    pd_mesh *m = mesh_new(a->nverts + b->nverts, a->ntris + b->ntris);
    memcpy(m->verts, a->verts, sizeof *m->verts * (size_t)a->nverts);
    memcpy(m->verts + a->nverts, b->verts, sizeof *m->verts * (size_t)b->nverts);
    memcpy(m->tris, a->tris, sizeof *m->tris * (size_t)a->ntris);
    for (int t = 0; t < b->ntris; t++)
        for (int k = 0; k < 3; k++)
            m->tris[a->ntris + t][k] = b->tris[t][k] + a->nverts;
    return m;
}

static void flip_tri(pd_mesh *m, int t)
{
    int tmp = m->tris[t][1];
    m->tris[t][1] = m->tris[t][2];
    m->tris[t][2] = tmp;
}

static void flip_all(pd_mesh *m)
{
    for (int t = 0; t < m->ntris; t++)
        flip_tri(m, t);
}

static int mesh_same(const pd_mesh *a, const pd_mesh *b)
{
    return a->nverts == b->nverts && a->ntris == b->ntris &&
           memcmp(a->verts, b->verts, sizeof *a->verts * (size_t)a->nverts) == 0 &&
           memcmp(a->tris, b->tris, sizeof *a->tris * (size_t)a->ntris) == 0;
}

static pd_mesh *box_at(double ax, double ay, double az, pd_vec3 c)
{
    static const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    pd_mesh *m = mesh_box(ax, ay, az);
    mesh_transform(m, id, 1.0, c);
    return m;
}

/* Prism over a counter-clockwise polygon poly (n corners in the xy plane,
 * z from 0 to h) with the given triangulation of the cap, outward oriented. */
static pd_mesh *extrude(const double (*poly)[2], int n, const int (*cap)[3], int ncap, double h)
{
    pd_mesh *m = mesh_new(2 * n, 2 * ncap + 2 * n);
    for (int i = 0; i < n; i++) {
        m->verts[i] = v3(poly[i][0], poly[i][1], 0.0);
        m->verts[n + i] = v3(poly[i][0], poly[i][1], h);
    }
    int t = 0;
    for (int i = 0; i < ncap; i++) {
        int bottom[3] = {cap[i][0], cap[i][2], cap[i][1]}; /* seen from below */
        memcpy(m->tris[t++], bottom, sizeof bottom);
        int top[3] = {n + cap[i][0], n + cap[i][1], n + cap[i][2]};
        memcpy(m->tris[t++], top, sizeof top);
    }
    for (int i = 0; i < n; i++) {
        /* For a counter-clockwise outline, edge x up points outwards. */
        int j = (i + 1) % n;
        int q1[3] = {i, j, n + j}, q2[3] = {i, n + j, n + i};
        memcpy(m->tris[t++], q1, sizeof q1);
        memcpy(m->tris[t++], q2, sizeof q2);
    }
    return m;
}

/* A solid's exact mass properties: volume, centre, inertia about the centre. */
typedef struct body {
    double V;
    pd_vec3 c;
    double I[3][3];
} body;

static body box_body(double ax, double ay, double az, pd_vec3 c)
{
    /* Direct integration over the box: I_xx = V (ay^2 + az^2) / 12, etc. */
    body b;
    memset(&b, 0, sizeof b);
    b.V = ax * ay * az;
    b.c = c;
    b.I[0][0] = b.V * (ay * ay + az * az) / 12.0;
    b.I[1][1] = b.V * (az * az + ax * ax) / 12.0;
    b.I[2][2] = b.V * (ax * ax + ay * ay) / 12.0;
    return b;
}

/* Superposition: sign +1 adds material, -1 removes it (a void). Each part's
 * inertia is carried to the common centre by the parallel-axis theorem,
 * I += V (|d|^2 Id - d d^T). */
static body superpose(const body *parts, const double *sign, int n)
{
    body r;
    memset(&r, 0, sizeof r);
    pd_vec3 m1 = v3(0, 0, 0);
    for (int i = 0; i < n; i++) {
        r.V += sign[i] * parts[i].V;
        m1 = v3_add(m1, v3_scale(parts[i].c, sign[i] * parts[i].V));
    }
    r.c = v3_scale(m1, 1.0 / r.V);
    for (int i = 0; i < n; i++) {
        pd_vec3 d = v3_sub(parts[i].c, r.c);
        double dv[3] = {d.x, d.y, d.z}, d2 = v3_dot(d, d);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                r.I[a][b] += sign[i] * (parts[i].I[a][b] +
                                        parts[i].V * ((a == b ? d2 : 0.0) - dv[a] * dv[b]));
    }
    return r;
}

static double trace3(const double (*I)[3]) { return I[0][0] + I[1][1] + I[2][2]; }

/* Volume relative, centre to rel times the radius of gyration (the part's
 * length scale), every inertia component to rel times the trace. */
static void check_body(const pd_mass *m, const body *e, double rel, const char *src)
{
    double tr = trace3(e->I), len = sqrt(tr / e->V);
    CHECK_REL(m->volume, e->V, rel, src);
    CHECK_NEAR(m->com.x, e->c.x, rel * len, src);
    CHECK_NEAR(m->com.y, e->c.y, rel * len, src);
    CHECK_NEAR(m->com.z, e->c.z, rel * len, src);
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            CHECK_NEAR(m->inertia[a][b], e->I[a][b], rel * tr, src);
}

static body mass_body(const pd_mass *m)
{
    body b;
    b.V = m->volume;
    b.c = m->com;
    memcpy(b.I, m->inertia, sizeof b.I);
    return b;
}

/* Orient (expecting nflip flips, -1: don't care) then compute. */
static pd_mass orient_and_mass(pd_mesh *m, int nflip)
{
    pd_mass out;
    memset(&out, 0, sizeof out);
    int nf = -1;
    CHECK_STATUS(pd_mesh_orient(m, &nf, NULL), PD_OK);
    if (nflip >= 0)
        CHECK_INT(nf, nflip);
    CHECK_STATUS(pd_mass_compute(m, &out, NULL), PD_OK);
    return out;
}

/* --- the L-shaped solid ------------------------------------------------------ */

/* L outline: [0,a]x[0,b] joined with [0,c]x[b,d] (c < a, b < d), extruded to
 * height h. Dyadic default dimensions keep every coordinate exact, also after
 * a translation by 1e6. */
static pd_mesh *mesh_L(double a, double b, double c, double d, double h)
{
    const double poly[6][2] = {{0, 0}, {a, 0}, {a, b}, {c, b}, {c, d}, {0, d}};
    /* Fan from the reflex corner 3, which sees every other corner. */
    static const int cap[4][3] = {{3, 4, 5}, {3, 5, 0}, {3, 0, 1}, {3, 1, 2}};
    return extrude(poly, 6, cap, 4, h);
}

static body body_L(double a, double b, double c, double d, double h)
{
    body parts[2] = {box_body(a, b, h, v3(a / 2, b / 2, h / 2)),
                     box_body(c, d - b, h, v3(c / 2, (b + d) / 2, h / 2))};
    const double sign[2] = {1, 1};
    return superpose(parts, sign, 2);
}

#define LA 2.0
#define LB 0.5
#define LC 0.75
#define LD 1.5
#define LH 0.25

/* --- tests ------------------------------------------------------------------------ */

static void test_box(void)
{
    const double dims[][3] = {{1, 1, 1}, {0.3, 1.7, 2.9}, {1e-3, 5.0, 0.07}};
    for (int i = 0; i < 3; i++) {
        pd_mesh *m = mesh_box(dims[i][0], dims[i][1], dims[i][2]);
        pd_mass out = orient_and_mass(m, 0); /* convex_mesh is already outward */
        body e = box_body(dims[i][0], dims[i][1], dims[i][2], v3(0, 0, 0));
        check_body(&out, &e, REL, REL_SRC);
        pd_mesh_free(m);
    }
}

static void test_prism(void)
{
    /* Regular n-gon of circumradius r: n isosceles triangles with apex at the
     * centre, legs r, apex angle t = 2 pi / n. Area A = (n/2) r^2 sin t. For a
     * triangle (0, p, q), integral of |x|^2 dA = (A_tri/6)(|p|^2 + |q|^2 + p.q)
     * (trace of the triangle covariance (A/12)(sum v v^T + s s^T)), here
     * (A_tri/6) r^2 (2 + cos t) = (A_tri/6) r^2 (1 + 2 cos^2(pi/n)). Summed:
     * J = A r^2 (1 + 2 cos^2(pi/n)) / 6. n-fold symmetry with n >= 3 makes
     * the in-plane second moments isotropic, J/2 each. For the prism of
     * height h centred at the origin: V = A h, I_zz = V r^2 (1 + 2cos^2(pi/n))/6,
     * I_xx = I_yy = V (r^2 (1 + 2 cos^2(pi/n)) / 12 + h^2 / 12). */
    const int ns[] = {3, 4, 5, 8, 17, 32};
    const double r = 0.7, h = 1.3;
    for (int i = 0; i < (int)(sizeof ns / sizeof ns[0]); i++) {
        int n = ns[i];
        pd_mesh *m = mesh_prism(n, r, h);
        pd_mass out = orient_and_mass(m, 0);
        double A = 0.5 * n * r * r * sin(2.0 * M_PI / n), cp = cos(M_PI / n);
        body e;
        memset(&e, 0, sizeof e);
        e.V = A * h;
        e.I[2][2] = e.V * r * r * (1.0 + 2.0 * cp * cp) / 6.0;
        e.I[0][0] = e.I[1][1] = e.V * (r * r * (1.0 + 2.0 * cp * cp) + h * h) / 12.0;
        check_body(&out, &e, REL, REL_SRC);
        pd_mesh_free(m);
    }
}

static void test_platonic(void)
{
    pd_vec3 p[64];
    /* Regular tetrahedron of edge a: V = a^3 / (6 sqrt 2), I = V a^2 / 20 about
     * every axis through the centre. Corners (1,1,1), ...: a = 2 sqrt 2,
     * V = 8/3, I = 16/15. */
    pd_mesh *m = convex_mesh(p, pts_tetrahedron(p));
    pd_mass out = orient_and_mass(m, 0);
    body e;
    memset(&e, 0, sizeof e);
    e.V = 8.0 / 3.0;
    e.I[0][0] = e.I[1][1] = e.I[2][2] = 16.0 / 15.0;
    check_body(&out, &e, REL, "closed form, regular tetrahedron; " REL_SRC);
    pd_mesh_free(m);

    /* Cube of edge 2: V = 8, I = V (4 + 4) / 12 = 16/3. */
    m = convex_mesh(p, pts_cube(p));
    out = orient_and_mass(m, 0);
    e.V = 8.0;
    e.I[0][0] = e.I[1][1] = e.I[2][2] = 16.0 / 3.0;
    check_body(&out, &e, REL, "closed form, cube; " REL_SRC);
    pd_mesh_free(m);

    /* Octahedron |x|+|y|+|z| <= 1: 8 corner simplices of volume 1/6, V = 4/3;
     * on the unit simplex the integral of x^2 is 2!/5! = 1/60 (Dirichlet), so
     * the integral of x^2 over the octahedron is 8/60 and I = 2 * 8/60 = 4/15
     * (= V a^2 / 10 with edge a = sqrt 2). */
    m = convex_mesh(p, pts_octahedron(p));
    out = orient_and_mass(m, 0);
    e.V = 4.0 / 3.0;
    e.I[0][0] = e.I[1][1] = e.I[2][2] = 4.0 / 15.0;
    check_body(&out, &e, REL, "closed form, octahedron; " REL_SRC);
    pd_mesh_free(m);

    /* Icosahedron and dodecahedron: any solid with the symmetry of a Platonic
     * solid has an isotropic inertia tensor and its centre at the origin. */
    for (int k = 0; k < 2; k++) {
        int n = k ? pts_dodecahedron(p) : pts_icosahedron(p);
        m = convex_mesh(p, n);
        out = orient_and_mass(m, 0);
        double i0 = out.inertia[0][0];
        CHECK(out.volume > 0.0);
        CHECK_REL(out.inertia[1][1], i0, REL, "isotropy by symmetry; " REL_SRC);
        CHECK_REL(out.inertia[2][2], i0, REL, "isotropy by symmetry; " REL_SRC);
        CHECK_NEAR(out.inertia[0][1], 0.0, REL * i0, "isotropy by symmetry; " REL_SRC);
        CHECK_NEAR(out.inertia[1][2], 0.0, REL * i0, "isotropy by symmetry; " REL_SRC);
        CHECK_NEAR(out.inertia[2][0], 0.0, REL * i0, "isotropy by symmetry; " REL_SRC);
        CHECK_NEAR(v3_norm(out.com), 0.0, REL, "centred by symmetry; " REL_SRC);
        pd_mesh_free(m);
    }
}

static void test_L_shape(void)
{
    pd_mesh *m = mesh_L(LA, LB, LC, LD, LH);
    pd_mass out = orient_and_mass(m, 0);
    body e = body_L(LA, LB, LC, LD, LH);
    check_body(&out, &e, REL, "superposition of two boxes; " REL_SRC);
    /* Not just the diagonal: the L has a genuine product of inertia. */
    CHECK(fabs(e.I[0][1]) > 0.01 * trace3(CR(e.I)));
    pd_mesh_free(m);

    /* Non-dyadic proportions. */
    m = mesh_L(1.3, 0.37, 0.41, 2.2, 0.9);
    out = orient_and_mass(m, 0);
    e = body_L(1.3, 0.37, 0.41, 2.2, 0.9);
    check_body(&out, &e, REL, "superposition of two boxes; " REL_SRC);
    pd_mesh_free(m);
}

static void test_rotation(void)
{
    test_rng rng = {12345};
    body e = body_L(LA, LB, LC, LD, LH);
    for (int trial = 0; trial < 8; trial++) {
        double R[3][3];
        rng_rotation(&rng, R);
        pd_mesh *m = mesh_L(LA, LB, LC, LD, LH);
        mesh_transform(m, CR(R), 1.0, v3(0, 0, 0));
        pd_mass out = orient_and_mass(m, 0);
        /* Expected: V unchanged, com' = R com, I' = R I R^T. */
        body r;
        r.V = e.V;
        r.c = rot_apply(CR(R), e.c);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++) {
                r.I[a][b] = 0.0;
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++)
                        r.I[a][b] += R[a][i] * e.I[i][j] * R[b][j];
            }
        check_body(&out, &r, REL, "rotation invariance, I' = R I R^T; " REL_SRC);
        pd_mesh_free(m);
    }
}

/* The mass properties by the textbook sum with apex at the origin and plain
 * summation: what pd_mass_compute would do without its reference point. */
static body naive_mass(const pd_mesh *m)
{
    double s[10] = {0};
    for (int t = 0; t < m->ntris; t++) {
        pd_vec3 a = m->verts[m->tris[t][0]], b = m->verts[m->tris[t][1]], c = m->verts[m->tris[t][2]];
        double d = v3_dot(a, v3_cross(b, c));
        pd_vec3 q = v3_add(v3_add(a, b), c);
        s[0] += d;
        s[1] += d * q.x;
        s[2] += d * q.y;
        s[3] += d * q.z;
        s[4] += d * (a.x * a.x + b.x * b.x + c.x * c.x + q.x * q.x);
        s[5] += d * (a.y * a.y + b.y * b.y + c.y * c.y + q.y * q.y);
        s[6] += d * (a.z * a.z + b.z * b.z + c.z * c.z + q.z * q.z);
    }
    body r;
    memset(&r, 0, sizeof r);
    r.V = s[0] / 6.0;
    r.c = v3_scale(v3(s[1], s[2], s[3]), 1.0 / (24.0 * r.V));
    double sxx = s[4] / 120.0 - r.V * r.c.x * r.c.x;
    double syy = s[5] / 120.0 - r.V * r.c.y * r.c.y;
    double szz = s[6] / 120.0 - r.V * r.c.z * r.c.z;
    r.I[0][0] = syy + szz;
    r.I[1][1] = szz + sxx;
    r.I[2][2] = sxx + syy;
    return r;
}

static void test_translation(void)
{
    /* Exact coordinates: the L's dyadic dimensions shifted by multiples of 1e6
     * are still exact doubles, so any change comes from the algorithm, not the
     * input. The centre shifts by t up to the rounding of the final addition
     * (one ulp of |t|); the inertia must not change. */
    const pd_vec3 t = v3(1e6, -3e6, 2.5e6);
    static const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    body e = body_L(LA, LB, LC, LD, LH);
    pd_mesh *m = mesh_L(LA, LB, LC, LD, LH);
    pd_mass at0 = orient_and_mass(m, 0);
    mesh_transform(m, id, 1.0, t);
    pd_mass far = orient_and_mass(m, 0);
    check_body(&at0, &e, REL, "superposition of two boxes; " REL_SRC);
    double tr = trace3(CR(at0.inertia));
    CHECK_REL(far.volume, at0.volume, REL, REL_SRC);
    CHECK_NEAR(far.com.x, at0.com.x + t.x, 2.0 * DBL_EPSILON * fabs(t.x), "1 ulp of |t|: final addition");
    CHECK_NEAR(far.com.y, at0.com.y + t.y, 2.0 * DBL_EPSILON * fabs(t.y), "1 ulp of |t|: final addition");
    CHECK_NEAR(far.com.z, at0.com.z + t.z, 2.0 * DBL_EPSILON * fabs(t.z), "1 ulp of |t|: final addition");
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            CHECK_NEAR(far.inertia[a][b], at0.inertia[a][b], REL * tr, "translation invariance; " REL_SRC);
    pd_mesh_free(m);

    /* A general (rotated) part 1e6 away: its coordinates themselves are
     * rounded to ulp(1e6) = 1.2e-10 m on a part of size ~1 m, which moves the
     * inertia by ~1e-10 relative; 1e-8 bounds that with a margin of 100. */
    test_rng rng = {777};
    double R[3][3];
    rng_rotation(&rng, R);
    pd_mesh *p = mesh_prism(7, 0.6, 0.9);
    mesh_transform(p, CR(R), 1.0, v3(0, 0, 0));
    pd_mass p0 = orient_and_mass(p, 0);
    mesh_transform(p, id, 1.0, v3(-1e6, 1e6, 1e6));
    pd_mass p1 = orient_and_mass(p, 0);
    tr = trace3(CR(p0.inertia));
    CHECK_REL(p1.volume, p0.volume, 1e-8, "input rounding at 1e6: ulp 1.2e-10 on size 1");
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            CHECK_NEAR(p1.inertia[a][b], p0.inertia[a][b], 1e-8 * tr,
                       "input rounding at 1e6: ulp 1.2e-10 on size 1");
    CHECK_NEAR(p1.com.x, p0.com.x - 1e6, 1e-9, "input rounding at 1e6: ulp 1.2e-10 m");
    CHECK_NEAR(p1.com.y, p0.com.y + 1e6, 1e-9, "input rounding at 1e6: ulp 1.2e-10 m");
    CHECK_NEAR(p1.com.z, p0.com.z + 1e6, 1e-9, "input rounding at 1e6: ulp 1.2e-10 m");

    /* The documented comparison: the same sums with the apex at the origin
     * (naive_mass) on the same far-away prism. The cross product b x c of two
     * corners ~1e6 m out is a difference of products of ~1e12 m^2 that round
     * by ~1e-4 m^2, and a.(b x c) multiplies that by |a| ~ 1e6 m: ~1e2 m^3 of
     * round-off per triangle for a volume of ~1 m^3, and second moments of
     * ~1e24 cancelling to ~0.1. Measured: the volume comes out ~25 times too
     * large and the inertia trace ~1e13 times, while pd_mass_compute stays
     * within the 1e-8 of the input's own rounding above. The checks fail if
     * the naive sum were ever accurate to 1e-6, i.e. if the reference point
     * did not matter. (The dyadic L above does not show it: there every
     * product happens to be exact.) */
    body naive = naive_mass(p);
    CHECK(!(fabs(naive.V - p0.volume) <= 1e-6 * p0.volume));
    CHECK(!(fabs(trace3(CR(naive.I)) - tr) <= 1e-6 * tr));
    /* ...while at the origin the naive sum agrees, so the loss is the offset's. */
    mesh_transform(p, id, 1.0, v3(1e6, -1e6, -1e6));
    body naive0 = naive_mass(p);
    CHECK_REL(naive0.V, p0.volume, 1e-8, "input rounding at 1e6, undone");
    CHECK_REL(trace3(CR(naive0.I)), tr, 1e-8, "input rounding at 1e6, undone");
    pd_mesh_free(p);
}

static void test_scale(void)
{
    /* x -> s x: V ~ s^3, com ~ s, I ~ s^5 (mass s^3 times length^2). */
    static const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const double scales[] = {1e-3, 0.37, 13.0, 1e3};
    body e = body_L(LA, LB, LC, LD, LH);
    for (int i = 0; i < 4; i++) {
        double s = scales[i];
        pd_mesh *m = mesh_L(LA, LB, LC, LD, LH);
        mesh_transform(m, id, s, v3(0, 0, 0));
        pd_mass out = orient_and_mass(m, 0);
        body r;
        r.V = e.V * s * s * s;
        r.c = v3_scale(e.c, s);
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                r.I[a][b] = e.I[a][b] * s * s * s * s * s;
        check_body(&out, &r, REL, "scaling V ~ s^3, I ~ s^5; " REL_SRC);
        pd_mesh_free(m);
    }
}

static void test_random_flips(void)
{
    test_rng rng = {2024};
    pd_vec3 p[64];
    for (int shape = 0; shape < 4; shape++) {
        pd_mesh *m = shape == 0   ? mesh_L(LA, LB, LC, LD, LH)
                     : shape == 1 ? mesh_prism(12, 0.5, 2.0)
                     : shape == 2 ? convex_mesh(p, pts_icosahedron(p))
                                  : convex_mesh(p, pts_dodecahedron(p));
        pd_mesh *orig = pd_mesh_clone(m);
        pd_mass ref = orient_and_mass(orig, 0);
        for (int trial = 0; trial < 5; trial++) {
            pd_mesh *w = pd_mesh_clone(m);
            int k = 0;
            for (int t = 0; t < w->ntris; t++)
                if (rng_uniform(&rng) < 0.5) {
                    flip_tri(w, t);
                    k++;
                }
            /* The outward orientation is unique, so orient must undo exactly
             * the k flips and give back the original triangles. */
            pd_mass out = orient_and_mass(w, k);
            CHECK(mesh_same(w, orig));
            body e = mass_body(&ref);
            check_body(&out, &e, 0.0, "same triangles, same result: exact");
            pd_mesh_free(w);
        }
        /* Inside out: every triangle flips back. */
        pd_mesh *w = pd_mesh_clone(m);
        flip_all(w);
        orient_and_mass(w, w->ntris);
        CHECK(mesh_same(w, orig));
        pd_mesh_free(w);
        pd_mesh_free(orig);
        pd_mesh_free(m);
    }
}

static void test_void(void)
{
    /* Box 4 x 3 x 2 with an off-centre box-shaped void 1 x 0.5 x 0.75:
     * V = 24 - 0.375, inertia by superposition with the void subtracted. */
    const pd_vec3 cin = v3(0.8, -0.4, 0.3);
    pd_mesh *outer = mesh_box(4, 3, 2), *inner = box_at(1, 0.5, 0.75, cin);
    body parts[2] = {box_body(4, 3, 2, v3(0, 0, 0)), box_body(1, 0.5, 0.75, cin)};
    const double sign[2] = {1, -1};
    body e = superpose(parts, sign, 2);

    /* Both shells given outward: the void's 12 triangles must flip. */
    pd_mesh *m = mesh_concat(outer, inner);
    pd_mass out = orient_and_mass(m, inner->ntris);
    check_body(&out, &e, REL, "superposition, void subtracted; " REL_SRC);
    pd_mesh *good = pd_mesh_clone(m);
    pd_mesh_free(m);

    /* Given correctly (void inward): nothing flips. */
    orient_and_mass(good, 0);
    /* Everything inside out: both shells flip. */
    flip_all(good);
    out = orient_and_mass(good, good->ntris);
    check_body(&out, &e, REL, "superposition, void subtracted; " REL_SRC);
    /* Outer shell inward, void already inward: only the shell flips. */
    for (int t = 0; t < outer->ntris; t++)
        flip_tri(good, t);
    out = orient_and_mass(good, outer->ntris);
    check_body(&out, &e, REL, "superposition, void subtracted; " REL_SRC);
    pd_mesh_free(good);
    pd_mesh_free(outer);
    pd_mesh_free(inner);

    /* Three levels, all given outward: shell 6^3, void 4^3, island 2^3 in the
     * void. Depth 0 and 2 are material, depth 1 the void: only it flips. */
    pd_mesh *a = mesh_box(6, 6, 6), *b = box_at(4, 4, 4, v3(0.5, 0, 0)),
            *c = box_at(2, 2, 2, v3(1.0, 0.5, 0));
    pd_mesh *ab = mesh_concat(a, b), *abc = mesh_concat(ab, c);
    body p3[3] = {box_body(6, 6, 6, v3(0, 0, 0)), box_body(4, 4, 4, v3(0.5, 0, 0)),
                  box_body(2, 2, 2, v3(1.0, 0.5, 0))};
    const double s3[3] = {1, -1, 1};
    e = superpose(p3, s3, 3);
    out = orient_and_mass(abc, b->ntris);
    check_body(&out, &e, REL, "superposition, shell - void + island; " REL_SRC);
    CHECK_REL(out.volume, 216.0 - 64.0 + 8.0, REL, REL_SRC);
    pd_mesh_free(a);
    pd_mesh_free(b);
    pd_mesh_free(c);
    pd_mesh_free(ab);
    pd_mesh_free(abc);
}

static void test_disjoint(void)
{
    /* Two separate boxes, the second given inside out: both are outer shells
     * (nested in nothing), so only the second's triangles flip and the
     * volumes add. */
    pd_mesh *a = box_at(1, 2, 3, v3(-3, 0, 0)), *b = box_at(0.5, 0.5, 2, v3(3, 1, 0.25));
    flip_all(b);
    pd_mesh *m = mesh_concat(a, b);
    body parts[2] = {box_body(1, 2, 3, v3(-3, 0, 0)), box_body(0.5, 0.5, 2, v3(3, 1, 0.25))};
    const double sign[2] = {1, 1};
    body e = superpose(parts, sign, 2);
    pd_mass out = orient_and_mass(m, b->ntris);
    check_body(&out, &e, REL, "superposition of two boxes; " REL_SRC);
    pd_mesh_free(a);
    pd_mesh_free(b);
    pd_mesh_free(m);

    /* Two unit cubes touching face to face (distinct vertices), the second
     * inside out. The second is placed across the face of the first's
     * triangle 0, so the first point orient probes lies on the other cube and
     * sees a winding number of 1/2; it must try further points and still find
     * both cubes to be outer shells. */
    a = box_at(1, 1, 1, v3(0, 0, 0));
    pd_vec3 n0 = v3_cross(v3_sub(a->verts[a->tris[0][1]], a->verts[a->tris[0][0]]),
                          v3_sub(a->verts[a->tris[0][2]], a->verts[a->tris[0][0]]));
    b = box_at(1, 1, 1, v3_unit(n0)); /* n0 is axis-aligned: the neighbour cell */
    flip_all(b);
    m = mesh_concat(a, b);
    pd_mass two = orient_and_mass(m, b->ntris);
    CHECK_REL(two.volume, 2.0, REL, REL_SRC);
    pd_mesh_free(a);
    pd_mesh_free(b);
    pd_mesh_free(m);
}

/* Runs orient expecting a failure; checks the status, that the mesh and
 * nflipped are untouched, and that the message contains want. */
static void expect_orient_failure(pd_mesh *m, pd_status status, const char *want)
{
    pd_mesh *before = pd_mesh_clone(m);
    pd_diag d;
    pd_diag_init(&d);
    int nf = -7;
    CHECK_STATUS(pd_mesh_orient(m, &nf, &d), status);
    CHECK_INT(nf, -7);
    CHECK(mesh_same(m, before));
    CHECK(strstr(d.message, want) != NULL);
    pd_mesh_free(before);
}

static void test_not_closed(void)
{
    /* Open: one triangle removed from a box, with the others flipped at
     * random so that orient would have work to do. */
    pd_mesh *m = mesh_box(1, 2, 3);
    m->ntris--;
    flip_tri(m, 2);
    expect_orient_failure(m, PD_ERR_NOT_CLOSED, "boundary");
    expect_orient_failure(m, PD_ERR_NOT_CLOSED, "1 face ");
    pd_mesh_free(m);

    /* Non-manifold: a fin (a third triangle) on the box edge of triangle 0. */
    pd_mesh *box = mesh_box(1, 2, 3);
    pd_mesh *fin = mesh_new(box->nverts + 1, box->ntris + 1);
    memcpy(fin->verts, box->verts, sizeof *box->verts * (size_t)box->nverts);
    memcpy(fin->tris, box->tris, sizeof *box->tris * (size_t)box->ntris);
    fin->verts[box->nverts] = v3(5, 5, 5);
    int t[3] = {box->tris[0][0], box->tris[0][1], box->nverts};
    memcpy(fin->tris[box->ntris], t, sizeof t);
    expect_orient_failure(fin, PD_ERR_NOT_CLOSED, "non-manifold");
    expect_orient_failure(fin, PD_ERR_NOT_CLOSED, "3 faces");
    pd_mesh_free(fin);
    pd_mesh_free(box);
}

static void test_non_orientable(void)
{
    /* The 6-vertex real projective plane (the hemi-icosahedron): 10
     * triangles, every one of the 15 vertex pairs an edge of exactly two. */
    static const int rp2[10][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 5}, {0, 5, 1},
                                   {1, 2, 4}, {2, 3, 5}, {3, 4, 1}, {4, 5, 2}, {5, 1, 3}};
    pd_mesh *m = mesh_new(6, 10);
    pts_octahedron(m->verts); /* any coordinates: the topology decides */
    memcpy(m->tris, rp2, sizeof rp2);
    /* Confirm it is closed, so the failure is about orientation alone. */
    int uses[6][6] = {{0}};
    for (int i = 0; i < 10; i++)
        for (int k = 0; k < 3; k++) {
            int a = rp2[i][k], b = rp2[i][(k + 1) % 3];
            uses[a][b]++;
            uses[b][a]++;
        }
    int all_two = 1;
    for (int a = 0; a < 6; a++)
        for (int b = a + 1; b < 6; b++)
            all_two = all_two && uses[a][b] == 2;
    CHECK(all_two);
    expect_orient_failure(m, PD_ERR_ORIENTATION, "non-orientable");
    pd_mesh_free(m);
}

static void test_flat(void)
{
    /* A doubled unit square, tilted and moved: top (0,1,2), (0,2,3) and a
     * bottom split along the other diagonal, so every edge has two faces.
     * Closed and orientable, but it encloses nothing. */
    test_rng rng = {99};
    double R[3][3];
    rng_rotation(&rng, R);
    pd_mesh *m = mesh_new(4, 4);
    m->verts[0] = v3(0, 0, 0);
    m->verts[1] = v3(1, 0, 0);
    m->verts[2] = v3(1, 1, 0);
    m->verts[3] = v3(0, 1, 0);
    static const int tris[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}};
    memcpy(m->tris, tris, sizeof tris);
    mesh_transform(m, CR(R), 1.0, v3(0.3, -2.0, 7.0));
    CHECK_STATUS(pd_mesh_orient(m, NULL, NULL), PD_OK);
    pd_mass sentinel, out;
    memset(&sentinel, 0x5a, sizeof sentinel);
    out = sentinel;
    pd_diag d;
    pd_diag_init(&d);
    CHECK_STATUS(pd_mass_compute(m, &out, &d), PD_ERR_COPLANAR);
    CHECK(memcmp(&out, &sentinel, sizeof out) == 0);
    CHECK(strstr(d.message, "flat") != NULL);
    pd_mesh_free(m);

    /* An inside-out box handed straight to pd_mass_compute: negative volume
     * is "not positive" as well, with its own message. */
    m = mesh_box(1, 1, 1);
    flip_all(m);
    pd_diag_init(&d);
    CHECK_STATUS(pd_mass_compute(m, &out, &d), PD_ERR_COPLANAR);
    CHECK(memcmp(&out, &sentinel, sizeof out) == 0);
    CHECK(strstr(d.message, "inwards") != NULL);
    pd_mesh_free(m);
}

static void test_degenerate_and_bad_input(void)
{
    /* A collapsed triangle (repeated vertex) adds nothing and is ignored by
     * both calls, with one warning from orient. */
    pd_mesh *box = mesh_box(1, 2, 3);
    pd_mesh *m = mesh_new(box->nverts, box->ntris + 1);
    memcpy(m->verts, box->verts, sizeof *box->verts * (size_t)box->nverts);
    memcpy(m->tris, box->tris, sizeof *box->tris * (size_t)box->ntris);
    int deg[3] = {4, 4, 1};
    memcpy(m->tris[box->ntris], deg, sizeof deg);
    pd_diag d;
    pd_diag_init(&d);
    int nf = -1;
    CHECK_STATUS(pd_mesh_orient(m, &nf, &d), PD_OK);
    CHECK_INT(nf, 0);
    CHECK_INT(d.nwarnings, 1);
    CHECK_INT(m->tris[box->ntris][0], 4);
    pd_mass out;
    CHECK_STATUS(pd_mass_compute(m, &out, NULL), PD_OK);
    body e = box_body(1, 2, 3, v3(0, 0, 0));
    check_body(&out, &e, REL, REL_SRC);

    /* Index out of range, non-finite vertex, NULL arguments. */
    m->tris[0][1] = m->nverts;
    CHECK_STATUS(pd_mesh_orient(m, NULL, NULL), PD_ERR_RANGE);
    CHECK_STATUS(pd_mass_compute(m, &out, NULL), PD_ERR_RANGE);
    m->tris[0][1] = box->tris[0][1];
    m->verts[2].y = NAN;
    CHECK_STATUS(pd_mesh_orient(m, NULL, NULL), PD_ERR_NONFINITE);
    CHECK_STATUS(pd_mass_compute(m, &out, NULL), PD_ERR_NONFINITE);
    CHECK_STATUS(pd_mesh_orient(NULL, NULL, NULL), PD_ERR_USAGE);
    CHECK_STATUS(pd_mass_compute(NULL, &out, NULL), PD_ERR_USAGE);
    CHECK_STATUS(pd_mass_compute(box, NULL, NULL), PD_ERR_USAGE);
    pd_mesh_free(m);

    /* Coordinates so large that the moments overflow: refused, not inf. */
    static const double id[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh_transform(box, id, 1e100, v3(0, 0, 0));
    CHECK_STATUS(pd_mass_compute(box, &out, NULL), PD_ERR_NONFINITE);
    pd_mesh_free(box);
}

/* A welded box of m x m squares per face, 12 m^2 triangles: the sums run
 * over ~1e5 terms and orient over ~1e5 triangles. */
static pd_mesh *lattice_box(int n, double ax, double ay, double az, pd_vec3 o)
{
    int side = n + 1;
    int *idx = malloc(sizeof *idx * (size_t)side * (size_t)side * (size_t)side);
    pd_mesh *m = mesh_new(6 * side * side, 12 * n * n);
    m->nverts = 0;
    const double len[3] = {ax, ay, az};
    for (int i = 0; i < side; i++)
        for (int j = 0; j < side; j++)
            for (int k = 0; k < side; k++) {
                int *slot = &idx[(i * side + j) * side + k];
                *slot = -1;
                if (i == 0 || j == 0 || k == 0 || i == n || j == n || k == n) {
                    m->verts[m->nverts] = v3(o.x + len[0] * i / n, o.y + len[1] * j / n,
                                             o.z + len[2] * k / n);
                    *slot = m->nverts++;
                }
            }
    m->ntris = 0;
    for (int f = 0; f < 3; f++)
        for (int hi = 0; hi < 2; hi++) {
            int u = (f + 1) % 3, w = (f + 2) % 3;
            for (int a = 0; a < n; a++)
                for (int b = 0; b < n; b++) {
                    int q[4];
                    for (int c = 0; c < 4; c++) {
                        int ijk[3];
                        ijk[f] = hi ? n : 0;
                        ijk[u] = a + (c == 1 || c == 2);
                        ijk[w] = b + (c >= 2);
                        q[c] = idx[(ijk[0] * side + ijk[1]) * side + ijk[2]];
                    }
                    /* q runs counter-clockwise around e_u x e_w = e_f: the
                     * outward normal of the high face, inward for the low. */
                    int t1[3] = {q[0], q[1], q[2]}, t2[3] = {q[0], q[2], q[3]};
                    if (!hi) {
                        int s = t1[1]; t1[1] = t1[2]; t1[2] = s;
                        s = t2[1]; t2[1] = t2[2]; t2[2] = s;
                    }
                    memcpy(m->tris[m->ntris++], t1, sizeof t1);
                    memcpy(m->tris[m->ntris++], t2, sizeof t2);
                }
        }
    free(idx);
    return m;
}

static void test_large(void)
{
    const pd_vec3 o = v3(0.3, -1.1, 2.0);
    pd_mesh *m = lattice_box(92, 1.5, 0.7, 2.3, o);
    CHECK(m->ntris > 100000);
    pd_mesh *orig = pd_mesh_clone(m);
    pd_mass ref = orient_and_mass(orig, 0);
    body e = box_body(1.5, 0.7, 2.3, v3(o.x + 0.75, o.y + 0.35, o.z + 1.15));
    check_body(&ref, &e, REL, "1e5 triangles, compensated sums; " REL_SRC);
    /* Compensated summation keeps a few ulps whatever the number of terms;
     * a plain sum over these 1e5 triangles was measured 3.5e-13 off in volume
     * and 6e-13 in inertia, so 1e-14 tells the two apart with room to spare. */
    check_body(&ref, &e, 1e-14, "compensated sums: a few ulps; plain sum 3.5e-13 off");

    test_rng rng = {31337};
    int k = 0;
    for (int t = 0; t < m->ntris; t++)
        if (rng_uniform(&rng) < 0.3) {
            flip_tri(m, t);
            k++;
        }
    orient_and_mass(m, k);
    CHECK(mesh_same(m, orig));
    pd_mesh_free(m);
    pd_mesh_free(orig);
}

void suite_mass(void)
{
    test_box();
    test_prism();
    test_platonic();
    test_L_shape();
    test_rotation();
    test_translation();
    test_scale();
    test_random_flips();
    test_void();
    test_disjoint();
    test_not_closed();
    test_non_orientable();
    test_flat();
    test_degenerate_and_bad_input();
    test_large();
}
