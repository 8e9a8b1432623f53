/* test_hull.c: the exact predicate and the convex hull.
 *
 * The predicate is checked against a slow exact reference (512-bit integer
 * arithmetic, no floating point) on near-degenerate inputs. The hull is
 * checked against closed forms (Platonic solids, boxes, prisms), against
 * qhull on random and degenerate clouds (facet by facet), for invariance
 * under rotation, scale and translation, and on the degenerate inputs the
 * merging must get right. pd_hull_check runs on every hull built here. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "hull/hull_internal.h"
#include "posedrop/hull.h"
#include "posedrop/tolerances.h"
#include "base/predicates.h"
#include "qhull_ref.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

/* --- slow exact reference: 512-bit two's complement integers ------------- */

#define BIG_LIMBS 16
typedef struct { uint32_t w[BIG_LIMBS]; } big;

static big big_add(big a, big b)
{
    big r;
    uint64_t carry = 0;
    for (int i = 0; i < BIG_LIMBS; i++) {
        uint64_t s = (uint64_t)a.w[i] + b.w[i] + carry;
        r.w[i] = (uint32_t)s;
        carry = s >> 32;
    }
    return r;
}

static big big_neg(big a)
{
    big one = {{1}};
    for (int i = 0; i < BIG_LIMBS; i++)
        a.w[i] = ~a.w[i];
    return big_add(a, one);
}

static big big_sub(big a, big b) { return big_add(a, big_neg(b)); }

/* Product modulo 2^512: exact whenever the true product fits, which the
 * callers guarantee by bounding the exponent spread of the inputs. */
static big big_mul(big a, big b)
{
    big r;
    memset(&r, 0, sizeof r);
    for (int i = 0; i < BIG_LIMBS; i++) {
        uint64_t carry = 0;
        for (int j = 0; i + j < BIG_LIMBS; j++) {
            uint64_t t = (uint64_t)a.w[i] * b.w[j] + r.w[i + j] + carry;
            r.w[i + j] = (uint32_t)t;
            carry = t >> 32;
        }
    }
    return r;
}

static int big_sign(big a)
{
    if (a.w[BIG_LIMBS - 1] >> 31)
        return -1;
    for (int i = 0; i < BIG_LIMBS; i++)
        if (a.w[i])
            return 1;
    return 0;
}

/* x * 2^-e0 as an integer (x must be a multiple of 2^e0). */
static big big_from_double(double x, int e0)
{
    big r;
    memset(&r, 0, sizeof r);
    if (x == 0.0)
        return r;
    int ex;
    double f = frexp(fabs(x), &ex);
    uint64_t m = (uint64_t)ldexp(f, 53);
    int shift = ex - 53 - e0;
    for (int b = 0; b < 53; b++)
        if (m >> b & 1) {
            int bit = b + shift;
            r.w[bit / 32] |= (uint32_t)1 << (bit % 32);
        }
    return x < 0 ? big_neg(r) : r;
}

/* Sign of (b - a) x (c - a) . (d - a), exactly, by integers. */
static int orient_ref(pd_vec3 a, pd_vec3 b, pd_vec3 c, pd_vec3 d)
{
    double x[12] = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z, d.x, d.y, d.z};
    int e0 = 100000;
    for (int i = 0; i < 12; i++)
        if (x[i] != 0.0) {
            int ex;
            frexp(x[i], &ex);
            if (ex - 53 < e0)
                e0 = ex - 53;
        }
    big v[12];
    for (int i = 0; i < 12; i++)
        v[i] = big_from_double(x[i], e0);
    big u[3], s[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = big_sub(v[3 + k], v[k]);
        s[k] = big_sub(v[6 + k], v[k]);
        w[k] = big_sub(v[9 + k], v[k]);
    }
    big det = big_mul(u[0], big_sub(big_mul(s[1], w[2]), big_mul(s[2], w[1])));
    det = big_add(det, big_mul(u[1], big_sub(big_mul(s[2], w[0]), big_mul(s[0], w[2]))));
    det = big_add(det, big_mul(u[2], big_sub(big_mul(s[0], w[1]), big_mul(s[1], w[0]))));
    return big_sign(det);
}

/* Is x - a exact? (Knuth's two-sum remainder of x and -a is zero.) */
static int diff_exact(double x, double a)
{
    double s = x - a, bv = s - x, av = s - bv;
    return (x - av) + (-a - bv) == 0.0;
}

static void test_predicate(void)
{
    test_rng rng = {1};
    int mismatches = 0, antisym = 0, zeros = 0, pos = 0, neg = 0, staged = 0;
    for (int i = 0; i < 3000; i++) {
        double off = i % 3 == 0 ? 0.0 : i % 3 == 1 ? 1e6 : 0.1;
        double sc = i % 2 ? 1.0 : 1e-3;
        pd_vec3 a = v3(off + sc * rng_range(&rng, -1, 1), off + sc * rng_range(&rng, -1, 1), sc * rng_range(&rng, -1, 1));
        pd_vec3 b = v3(off + sc * rng_range(&rng, -1, 1), off + sc * rng_range(&rng, -1, 1), sc * rng_range(&rng, -1, 1));
        pd_vec3 c = v3(off + sc * rng_range(&rng, -1, 1), off + sc * rng_range(&rng, -1, 1), sc * rng_range(&rng, -1, 1));
        double s = rng_range(&rng, -1, 2), t = rng_range(&rng, -1, 2);
        /* d on the plane abc up to rounding, then nudged by a few ulps */
        pd_vec3 d = v3_add(a, v3_add(v3_scale(v3_sub(b, a), s), v3_scale(v3_sub(c, a), t)));
        int nudge = (int)(rng_next(&rng) % 7) - 3;
        for (int k = 0; k < abs(nudge); k++)
            d.z = nextafter(d.z, nudge > 0 ? INFINITY : -INFINITY);
        if (i % 5 == 0) { /* exactly coplanar: a grid plane z = const */
            a.z = b.z = c.z = d.z;
        }
        if (i % 7 == 0) { /* exactly collinear a, b, c */
            b = a;
            b.x = nextafter(a.x, INFINITY);
        }
        int got = pd_orient3d(&a, &b, &c, &d), want = orient_ref(a, b, c, d);
        mismatches += got != want;
        /* the precomputed-plane form used by quickhull */
        pd_vec3 u = v3_sub(b, a), w = v3_sub(c, a), n = v3_cross(u, w);
        pd_vec3 np = v3(fabs(u.y * w.z) + fabs(u.z * w.y), fabs(u.z * w.x) + fabs(u.x * w.z),
                        fabs(u.x * w.y) + fabs(u.y * w.x));
        mismatches += pd_orient3d_plane(&n, &np, &a, &b, &c, &d) != want;
        /* the exact fallback on every case, whether its differences are
         * exact (its first stage: offset 0 and 1e6 mostly) or not (0.1,
         * points straddling it, mostly the full expansion) */
        mismatches += pd_orient3d_exact(&a, &b, &c, &d) != want;
        int exact_diff = 1;
        const pd_vec3 *pt[3] = {&b, &c, &d};
        for (int k = 0; k < 3; k++)
            exact_diff &= diff_exact(pt[k]->x, a.x) && diff_exact(pt[k]->y, a.y) &&
                          diff_exact(pt[k]->z, a.z);
        staged += exact_diff;
        antisym += pd_orient3d(&b, &a, &c, &d) != -got || pd_orient3d(&a, &b, &d, &c) != -got;
        zeros += want == 0;
        pos += want > 0;
        neg += want < 0;
    }
    CHECK_INT(mismatches, 0);
    CHECK_INT(antisym, 0);
    /* the cases must exercise all three answers, or the test proves little */
    CHECK(zeros > 100 && pos > 100 && neg > 100);
    /* both stages of the fallback ran on hundreds of cases */
    CHECK(staged > 300 && 3000 - staged > 300);
    /* tiny determinants decided by the exact path alone */
    pd_vec3 a = v3(0.5, 0.5, 0.5), b = v3(12, 12, 12), c = v3(24, 24, 24.0), d = v3(0.5, 0.5, 0.5);
    c.y = nextafter(24.0, 25.0);
    d.z = nextafter(0.5, 1.0);
    CHECK_INT(pd_orient3d(&a, &b, &c, &d), orient_ref(a, b, c, d));
    CHECK_INT(pd_orient3d_exact(&a, &b, &c, &d), orient_ref(a, b, c, d));
    CHECK(orient_ref(a, b, c, d) != 0);
}

/* --- hull helpers ----------------------------------------------------------- */

static pd_hull *build_checked(const pd_vec3 *p, int n)
{
    pd_hull *h = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_hull_build(p, n, &h, &d);
    CHECK_STATUS(st, PD_OK);
    if (st != PD_OK) {
        printf("     pd_hull_build: %s (n = %d)\n", d.message, n);
        return NULL;
    }
    st = pd_hull_check(h, p, n, &d);
    CHECK_STATUS(st, PD_OK);
    if (st != PD_OK)
        printf("     pd_hull_check: %s\n", d.message);
    return h;
}

typedef struct { double x; int i; } keyed;

static int cmp_keyed(const void *a, const void *b)
{
    double x = ((const keyed *)a)->x, y = ((const keyed *)b)->x;
    return (x > y) - (x < y);
}

/* Normals of the same plane from different vertex choices agree to ~1e-15
 * rad; genuine neighbouring facets differ by >= 1e-7 rad (tolerances.h). */
#define NORMAL_MATCH_ANGLE 1e-9
/* Volumes are sums of <= 2e6 tetrahedra, each to ~1e-16 relative. */
#define VOLUME_REL 1e-12

/* Same facet count as qhull, every facet's normal matched one-to-one to a
 * qhull facet within NORMAL_MATCH_ANGLE, same volume.
 *
 * qhull (default options) merges only what its round-off makes coplanar, we
 * merge what lies within PD_TOL_PLANE_REL * size of one plane. qhull's
 * option for a wider merge ("Cn", centrum radius) tests a facet's centrum,
 * not all its vertices, so it would not reproduce our facets exactly; the
 * exact comparisons therefore use clouds and sizes where no neighbouring hull
 * triangles come within 1e-7 of one plane (checked: the facet counts agree).
 * Larger clouds do have such pairs (their number grows like n^2 for random
 * points on a sphere: ~50 at 10^4 points). For those, max_merged > 0 allows
 * that many qhull facets to be missing: each merged facet of ours replaces
 * k >= 2 of qhull's and matches none of them, so at most that many of ours
 * go unmatched. The volume must agree to 1e-12 everywhere: it is summed from
 * the exact triangulation, which merging does not touch. */
static void compare_qhull_merged(const pd_vec3 *p, int n, int max_merged, const char *what)
{
    pd_hull *h = build_checked(p, n);
    qhull_ref q;
    int rc = qhull_ref_build(p, n, &q);
    CHECK_INT(rc, 0);
    if (!h || rc != 0) {
        printf("     in %s\n", what);
        pd_hull_free(h);
        return;
    }
    int before = pd_checks_failed;
    int missing = q.nfacets - h->nfacets;
    if (max_merged == 0)
        CHECK_INT(h->nfacets, q.nfacets);
    else
        CHECK(missing >= 0 && missing <= max_merged);
    keyed *k = malloc(sizeof *k * (size_t)q.nfacets);
    char *used = calloc((size_t)q.nfacets, 1);
    for (int i = 0; i < q.nfacets; i++) {
        k[i].x = q.normal[i].x;
        k[i].i = i;
    }
    qsort(k, (size_t)q.nfacets, sizeof *k, cmp_keyed);
    int unmatched = 0;
    double worst = 0.0;
    for (int f = 0; f < h->nfacets; f++) {
        pd_vec3 nf = h->normal[f];
        /* candidates: qhull normals whose x is within the angle of nf.x */
        int lo = 0, hi = q.nfacets;
        while (lo < hi) {
            int mid = (lo + hi) / 2;
            if (k[mid].x < nf.x - NORMAL_MATCH_ANGLE)
                lo = mid + 1;
            else
                hi = mid;
        }
        int best = -1;
        double bang = INFINITY;
        for (int j = lo; j < q.nfacets && k[j].x <= nf.x + NORMAL_MATCH_ANGLE; j++) {
            double ang = v3_angle(nf, q.normal[k[j].i]);
            if (!used[k[j].i] && ang < bang) {
                bang = ang;
                best = k[j].i;
            }
        }
        if (best < 0 || !(bang < NORMAL_MATCH_ANGLE)) {
            unmatched++;
            continue;
        }
        used[best] = 1;
        worst = fmax(worst, bang);
    }
    if (max_merged == 0)
        CHECK_INT(unmatched, 0);
    else
        CHECK(unmatched <= missing);
    CHECK_NEAR(worst, 0.0, NORMAL_MATCH_ANGLE, "same plane: normals agree to round-off, ~1e-15 rad");
    CHECK_REL(h->volume, q.volume, VOLUME_REL, "sum of tetrahedra, round-off ~1e-16 each");
    if (pd_checks_failed != before)
        printf("     in %s (n = %d)\n", what, n);
    free(k);
    free(used);
    qhull_ref_free(&q);
    pd_hull_free(h);
}

static void compare_qhull(const pd_vec3 *p, int n, const char *what) { compare_qhull_merged(p, n, 0, what); }

static pd_vec3 rand_cube(test_rng *r) { return v3(rng_range(r, -1, 1), rng_range(r, -1, 1), rng_range(r, -1, 1)); }

static pd_vec3 rand_ball(test_rng *r)
{
    for (;;) {
        pd_vec3 p = rand_cube(r);
        if (v3_dot(p, p) <= 1.0)
            return p;
    }
}

/* --- closed forms --------------------------------------------------------- */

static void solid(const pd_vec3 *p, int n, int nfacets, int nverts, double volume, const char *what)
{
    pd_hull *h = build_checked(p, n);
    if (!h)
        return;
    int before = pd_checks_failed;
    CHECK_INT(h->nfacets, nfacets);
    CHECK_INT(h->nverts, nverts);
    CHECK_REL(h->volume, volume, 1e-12, "closed form; round-off ~1e-16");
    if (pd_checks_failed != before)
        printf("     in %s\n", what);
    pd_hull_free(h);
}

static void test_solids(void)
{
    pd_vec3 p[64];
    double g = (1.0 + sqrt(5.0)) / 2.0;
    solid(p, pts_tetrahedron(p), 4, 4, 8.0 / 3.0, "tetrahedron");
    solid(p, pts_cube(p), 6, 8, 8.0, "cube");
    solid(p, pts_octahedron(p), 8, 6, 4.0 / 3.0, "octahedron");
    /* dodecahedron of edge 2/g, icosahedron of edge 2 */
    double a = 2.0 / g;
    solid(p, pts_dodecahedron(p), 12, 20, (15.0 + 7.0 * sqrt(5.0)) / 4.0 * a * a * a, "dodecahedron");
    solid(p, pts_icosahedron(p), 20, 12, 5.0 / 12.0 * (3.0 + sqrt(5.0)) * 8.0, "icosahedron");
    solid(p, pts_box(1, 2, 3, p), 6, 8, 6.0, "box 1 x 2 x 3");
    int sides[] = {3, 5, 8, 17, 32};
    for (int i = 0; i < 5; i++) {
        int k = sides[i];
        solid(p, pts_prism(k, 0.7, 1.3, p), k + 2, 2 * k, 0.5 * k * 0.49 * sin(2.0 * M_PI / k) * 1.3, "prism");
    }
    /* a cube's facets are squares, counter-clockwise: corners of 4 each */
    pd_hull *h = build_checked(p, pts_cube(p));
    if (h)
        for (int f = 0; f < h->nfacets; f++)
            CHECK_INT(h->facet_start[f + 1] - h->facet_start[f], 4);
    pd_hull_free(h);
}

/* --- qhull comparisons ------------------------------------------------------ */

static void test_vs_qhull_random(void)
{
    test_rng rng = {2};
    /* Facet for facet up to these sizes (no near-coplanar neighbours at
     * 1e-7 there, see compare_qhull_merged): in a cube and a ball up to 10^4
     * points, whose hulls have a few hundred facets; on a sphere, where every
     * point is a vertex and neighbours are flatter, up to 1000 (2000 already
     * has 4 such pairs). */
    int sizes[] = {10, 100, 1000, 2000, 10000};
    pd_vec3 *p = malloc(sizeof *p * 100000);
    for (int s = 0; s < 5; s++) {
        int n = sizes[s];
        for (int i = 0; i < n; i++)
            p[i] = rand_cube(&rng);
        compare_qhull(p, n, "uniform in a cube");
        for (int i = 0; i < n; i++)
            p[i] = rand_ball(&rng);
        compare_qhull(p, n, "uniform in a ball");
        if (n <= 1000) {
            for (int i = 0; i < n; i++)
                p[i] = rng_unit_vector(&rng);
            compare_qhull(p, n, "on a sphere");
        }
    }
    /* Larger: a few near-coplanar neighbours merge (bounded: under 1% of
     * qhull's facets), the volume still agrees to 1e-12. */
    for (int i = 0; i < 100000; i++)
        p[i] = rand_cube(&rng);
    compare_qhull_merged(p, 100000, 5, "uniform in a cube");
    for (int i = 0; i < 2000; i++)
        p[i] = rng_unit_vector(&rng);
    compare_qhull_merged(p, 2000, 40, "on a sphere");
    for (int i = 0; i < 10000; i++)
        p[i] = rng_unit_vector(&rng);
    compare_qhull_merged(p, 10000, 200, "on a sphere");
    for (int i = 0; i < 20000; i++)
        p[i] = rand_ball(&rng);
    compare_qhull_merged(p, 20000, 20, "uniform in a ball");
    free(p);
}

static void test_vs_qhull_degenerate(void)
{
    enum { MAXP = 4000 };
    pd_vec3 *p = malloc(sizeof *p * MAXP);
    test_rng rng = {3};
    int n;
    /* cospherical: vertices of a Platonic solid plus their antipodes, all on
     * one sphere, and random unit vectors: every point is a vertex */
    n = pts_icosahedron(p);
    n += pts_dodecahedron(p + n);
    for (int i = 0; i < n; i++)
        p[i] = v3_unit(p[i]);
    compare_qhull(p, n, "icosahedron + dodecahedron on one sphere");
    /* cocircular: two parallel circles (prism) and a circle plus an apex (cone) */
    n = 0;
    for (int i = 0; i < 200; i++) {
        double t = 2.0 * M_PI * i / 200;
        p[n++] = v3(cos(t), sin(t), 0.0);
        p[n++] = v3(cos(t), sin(t), 0.5);
    }
    compare_qhull(p, n, "two parallel circles");
    pd_hull *h = build_checked(p, n);
    if (h)
        CHECK_INT(h->nfacets, 202);
    pd_hull_free(h);
    n = 0;
    for (int i = 0; i < 300; i++) {
        double t = 2.0 * M_PI * i / 300;
        p[n++] = v3(cos(t), sin(t), 0.0);
    }
    p[n++] = v3(0.1, 0.2, 2.0);
    compare_qhull(p, n, "circle plus apex (cone)");
    h = build_checked(p, n);
    if (h)
        CHECK_INT(h->nfacets, 301);
    pd_hull_free(h);
    /* integer grid */
    n = 0;
    for (int i = 0; i < 10; i++)
        for (int j = 0; j < 10; j++)
            for (int k = 0; k < 10; k++)
                p[n++] = v3(i, j, k);
    compare_qhull(p, n, "10 x 10 x 10 grid");
    solid(p, n, 6, 8, 729.0, "10 x 10 x 10 grid");
    /* sliver: a flat 1 x 1 x 1e-6 box, corners plus points inside and on faces */
    n = pts_box(1, 1, 1e-6, p);
    for (int i = 0; i < 500; i++)
        p[n++] = v3(rng_range(&rng, -0.5, 0.5), rng_range(&rng, -0.5, 0.5), i % 2 ? 0.5e-6 : rng_range(&rng, -0.5e-6, 0.5e-6));
    compare_qhull(p, n, "1 x 1 x 1e-6 sliver box");
    solid(p, n, 6, 8, 1e-6, "1 x 1 x 1e-6 sliver box");
    /* duplicates: every cube corner 50 times, random points inside */
    n = 0;
    for (int r = 0; r < 50; r++)
        n += pts_cube(p + n);
    for (int i = 0; i < 300; i++)
        p[n++] = v3_scale(rand_cube(&rng), 0.999);
    compare_qhull(p, n, "cube corners repeated 50 times");
    solid(p, n, 6, 8, 8.0, "cube corners repeated 50 times");
    /* points on edges and faces of a box (exactly: dyadic steps) */
    n = pts_box(2, 2, 2, p);
    for (int i = 1; i < 64; i++) {
        double t = -1.0 + i / 32.0;
        p[n++] = v3(t, -1, -1);
        p[n++] = v3(1, t, 1);
        p[n++] = v3(-1, 1, t);
        p[n++] = v3(t, 0.25, 1);
    }
    compare_qhull(p, n, "box with points on edges and faces");
    solid(p, n, 6, 8, 8.0, "box with points on edges and faces");
    free(p);
}

/* --- invariance --------------------------------------------------------------- */

static void test_invariance(void)
{
    enum { N = 2000 };
    pd_vec3 *base = malloc(sizeof *base * N), *p = malloc(sizeof *p * N);
    test_rng rng = {4};
    for (int i = 0; i < N; i++)
        base[i] = rand_ball(&rng);
    pd_vec3 box[64];
    int nbox = pts_box(1, 2, 3, box);
    pd_hull *h0 = build_checked(base, N);
    if (!h0)
        return;
    const double scales[] = {1e-3, 1.0, 1e3};
    for (int r = 0; r < 4; r++) {
        double R[3][3];
        rng_rotation(&rng, R);
        for (int s = 0; s < 3; s++) {
            memcpy(p, base, sizeof *p * N);
            points_transform(p, N, (const double (*)[3])R, scales[s], v3(0, 0, 0));
            pd_hull *h = build_checked(p, N);
            if (h) {
                CHECK_INT(h->nfacets, h0->nfacets);
                CHECK_REL(h->volume, h0->volume * pow(scales[s], 3), 1e-12, "rotation round-off ~1e-16");
            }
            pd_hull_free(h);
            pd_vec3 b[8];
            memcpy(b, box, sizeof b);
            points_transform(b, nbox, (const double (*)[3])R, scales[s], v3(0, 0, 0));
            solid(b, nbox, 6, 8, 6.0 * pow(scales[s], 3), "rotated scaled box");
        }
    }
    /* Translation by 1e6: points on a grid of step 2^-33 (>= 1e6 * 2^-53)
     * so that the translated coordinates are exact and the two sets are
     * exactly congruent; sizes 2^-10 .. 2^10 (about 1e-3 .. 1e3). */
    const double q = ldexp(1.0, -33);
    for (int e = -10; e <= 10; e += 10) {
        double s = ldexp(1.0, e);
        for (int i = 0; i < N; i++)
            p[i] = v3(round(base[i].x * s / q) * q, round(base[i].y * s / q) * q, round(base[i].z * s / q) * q);
        pd_hull *ha = build_checked(p, N);
        for (int i = 0; i < N; i++)
            p[i] = v3_add(p[i], v3(1e6, -1e6, 1e6));
        pd_hull *hb = build_checked(p, N);
        if (ha && hb) {
            CHECK_INT(hb->nfacets, ha->nfacets);
            CHECK_INT(hb->nverts, ha->nverts);
            CHECK_REL(ha->volume, h0->volume * s * s * s, 1e-6, "grid rounding 2^-33 / size moves points ~1e-7");
            CHECK_REL(hb->volume, ha->volume, 1e-12, "same points, round-off of relative coordinates");
        }
        pd_hull_free(ha);
        pd_hull_free(hb);
        pd_vec3 b[8];
        nbox = pts_box(s, 2 * s, 4 * s, b);
        for (int i = 0; i < nbox; i++)
            b[i] = v3_add(b[i], v3(1e6, 1e6, -1e6));
        solid(b, nbox, 6, 8, 8.0 * s * s * s, "translated box");
    }
    pd_hull_free(h0);
    free(base);
    free(p);
}

/* --- merging ------------------------------------------------------------------ */

/* A box of half-width w and depth below a roof whose two halves slope by
 * crease / 2 each, so they meet at the ridge at the angle crease. */
static pd_hull *build_roof(pd_vec3 *p, double w, double depth, double crease)
{
    int n = 0;
    double drop = w * tan(crease / 2.0);
    for (int y = 0; y <= 1; y++) {
        p[n++] = v3(-w, y, -drop);
        p[n++] = v3(0, y, 0);
        p[n++] = v3(w, y, -drop);
        p[n++] = v3(-w, y, -depth);
        p[n++] = v3(w, y, -depth);
    }
    return build_checked(p, n);
}

/* Angle between the two upward roof facets (0 if there are fewer). */
static double roof_angle(const pd_hull *h)
{
    double best = 0.0;
    for (int f = 0; f < h->nfacets; f++)
        for (int g = 0; g < h->nfacets; g++)
            if (h->normal[f].z > 0.9 && h->normal[g].z > 0.9 && f != g)
                best = v3_angle(h->normal[f], h->normal[g]);
    return best;
}

/* z = -c x^2 on x in [-0.5, 0.5], y in {0, 1}, in nstrips strips, over a
 * block down to z = -1; the last 4 points are the block's bottom. */
static int parabolic_strips(pd_vec3 *p, int nstrips, double c)
{
    int n = 0;
    for (int i = 0; i <= nstrips; i++) {
        double x = -0.5 + (double)i / nstrips;
        p[n++] = v3(x, 0, -c * x * x);
        p[n++] = v3(x, 1, -c * x * x);
    }
    p[n++] = v3(-0.5, 0, -1);
    p[n++] = v3(0.5, 0, -1);
    p[n++] = v3(-0.5, 1, -1);
    p[n++] = v3(0.5, 1, -1);
    return n;
}

/* A shallow paraboloid cap z = -c r^2 (r <= 1) on a polar grid of nrings
 * rings of m points (alternate rings turned by half a step) and a centre,
 * over a disc of m points at z = -1. Where the cap's curvature is a few
 * tolerances over its width, region growing finds rings of triangles within
 * the tolerance of one plane around a centre that bulges out of it. */
static int paraboloid_cap(pd_vec3 *p, int nrings, int m, double c)
{
    int n = 0;
    p[n++] = v3(0, 0, 0);
    for (int i = 1; i <= nrings; i++) {
        double r = (double)i / nrings;
        for (int j = 0; j < m; j++) {
            double t = 2.0 * M_PI * (j + 0.5 * (i % 2)) / m;
            p[n++] = v3(r * cos(t), r * sin(t), -c * r * r);
        }
    }
    for (int j = 0; j < m; j++) {
        double t = 2.0 * M_PI * j / m;
        p[n++] = v3(cos(t), sin(t), -1);
    }
    return n;
}

/* The merge's repairs, on inputs where the plane test alone fails: before
 * the disc rule, the first cap grew a facet that was not a disc (an
 * annulus, PD_ERR_INTERNAL), and the second left a facet with two corners
 * (PD_ERR_COPLANAR). Each must now reach its repair (the counters say so),
 * give a hull that passes pd_hull_check, and keep qhull's volume. */
static void test_merge_repair(void)
{
    pd_vec3 *p = malloc(sizeof *p * 1000);
    const struct { int nrings, m; double c; int disc, dissolve; } cap[] = {
        {8, 48, 1.6e-6, 1, 0},
        {8, 24, 8e-7, 0, 1},
    };
    for (int k = 0; k < 2; k++) {
        int n = paraboloid_cap(p, cap[k].nrings, cap[k].m, cap[k].c);
        pd_hull *h = NULL;
        pd_hull_merge_stats ms;
        memset(&ms, 0, sizeof ms);
        pd_diag d;
        pd_diag_init(&d);
        pd_status st = pd_hull_build_stats(p, n, &h, &ms, &d);
        CHECK_STATUS(st, PD_OK);
        if (st != PD_OK) {
            printf("     pd_hull_build: %s (cap %d)\n", d.message, k);
            continue;
        }
        CHECK_STATUS(pd_hull_check(h, p, n, &d), PD_OK);
        if (cap[k].disc)
            CHECK(ms.disc_rejects > 0);
        if (cap[k].dissolve)
            CHECK(ms.dissolved_regions > 0 && ms.repair_passes > 0);
        /* the cap must still be merged, not left as its triangles */
        int top = 0;
        for (int f = 0; f < h->nfacets; f++)
            top += h->normal[f].z > 0.5;
        CHECK(top < 2 * cap[k].nrings * cap[k].m);
        qhull_ref q;
        if (qhull_ref_build(p, n, &q) == 0) {
            CHECK_REL(h->volume, q.volume, VOLUME_REL, "sum of tetrahedra of the exact triangulation");
            qhull_ref_free(&q);
        } else {
            CHECK(0);
        }
        pd_hull_free(h);
    }
    free(p);
}

static void test_merging(void)
{
    enum { MAXP = 20000 };
    pd_vec3 *p = malloc(sizeof *p * MAXP);
    test_rng rng = {5};
    /* A box whose top face is fanned into thousands of slivers: thousands of
     * points on the top edges (collinear with the corners), a few inside the
     * top face, plus points on the other edges; rotated so nothing is exactly
     * collinear or coplanar any more. Must be the plain box. */
    for (int rot = 0; rot < 2; rot++) {
        int n = pts_box(2, 1, 0.5, p);
        for (int i = 1; i < 2000; i++) {
            double t = i / 2000.0;
            p[n++] = v3(-1 + 2 * t, -0.5, 0.25);
            p[n++] = v3(-1 + 2 * t, 0.5, 0.25);
            p[n++] = v3(-1, -0.5 + t, 0.25);
            p[n++] = v3(1, -0.5 + t, 0.25);
            if (i % 10 == 0) {
                p[n++] = v3(1, 0.5, -0.25 + 0.5 * t);
                p[n++] = v3(rng_range(&rng, -1, 1), rng_range(&rng, -0.5, 0.5), 0.25);
            }
        }
        if (rot) {
            double R[3][3];
            rng_rotation(&rng, R);
            points_transform(p, n, (const double (*)[3])R, 1.0, v3(0, 0, 0));
        }
        solid(p, n, 6, 8, 1.0, rot ? "rotated fanned box" : "fanned box");
    }
    /* A crease of 1e-7 rad is print noise and merges (tolerances.h); one
     * of 1e-5 rad over facets 0.1 to 0.4 of the part's size is a feature and
     * stays: the two roof halves are then 1.2e-6 and 2.5e-6 of the size off
     * one plane, far above 1e-7. */
    pd_hull *h = build_roof(p, 1.0, 1.0, 1e-7);
    if (h)
        CHECK_INT(h->nfacets, 6);
    pd_hull_free(h);
    h = build_roof(p, 1.0, 1.0, 1e-5);
    if (h) {
        CHECK_INT(h->nfacets, 7);
        CHECK_NEAR(roof_angle(h), 1e-5, 1e-12, "roof built to 1e-5 rad; normals to round-off");
    }
    pd_hull_free(h);
    h = build_roof(p, 0.5, 4.0, 1e-5);
    if (h) {
        CHECK(0.5 / h->size > 0.1 && 0.5 / h->size < 0.15);
        CHECK_INT(h->nfacets, 7);
        CHECK_NEAR(roof_angle(h), 1e-5, 1e-12, "roof built to 1e-5 rad; normals to round-off");
    }
    pd_hull_free(h);
    /* A parabolic cylinder z = -c x^2 over a unit square, tessellated into
     * strips, on both sides of the threshold. c = 0.05, 100 strips: two
     * neighbouring strips are c (2 / 100)^2 / 8 = 2.5e-6 off one plane, 14
     * times the tolerance: every strip is its own facet (its four corners
     * are exactly coplanar), plus the bottom, two sides and two ends. */
    int n = parabolic_strips(p, 100, 0.05);
    h = build_checked(p, n);
    if (h)
        CHECK_INT(h->nfacets, 100 + 5);
    pd_hull_free(h);
    /* c = 5e-6, 1000 strips: neighbours are 5e-12 off one plane and merge,
     * but the whole arc is c / 8 = 6e-7 (3.6 tolerances) off its best plane,
     * so it must not become one facet: a merged facet spans at most
     * sqrt(8 tol / c) = 0.53 of the arc, so at least 2 facets, and regions
     * grown greedily stay close to that. Every point must lie within the
     * tolerance of a facet plane (no vertex of a merged facet drifts off
     * its plane). */
    n = parabolic_strips(p, 1000, 5e-6);
    h = build_checked(p, n);
    if (h) {
        CHECK(h->nfacets >= 2 + 5 && h->nfacets <= 10 + 5);
        double worst = 0.0;
        for (int i = 0; i < n - 4; i++) {
            double best = INFINITY;
            for (int f = 0; f < h->nfacets; f++)
                best = fmin(best, fabs(v3_dot(h->normal[f], p[i]) - h->offset[f]));
            worst = fmax(worst, best);
        }
        CHECK_NEAR(worst, 0.0, PD_TOL_PLANE_REL * h->size, "PD_TOL_PLANE_REL: merged facets stay planar");
    }
    pd_hull_free(h);
    free(p);
}

/* --- degenerate input ------------------------------------------------------------ */

static void expect_status(const pd_vec3 *p, int n, pd_status want)
{
    pd_hull *h = NULL;
    pd_diag d;
    pd_diag_init(&d);
    CHECK_STATUS(pd_hull_build(p, n, &h, &d), want);
    CHECK(h == NULL);
    CHECK(d.message[0] != '\0');
}

static void test_degenerate_status(void)
{
    pd_vec3 p[100];
    test_rng rng = {6};
    pts_cube(p);
    expect_status(p, 3, PD_ERR_TOO_FEW_POINTS);
    expect_status(p, 0, PD_ERR_TOO_FEW_POINTS);
    p[5].y = NAN;
    expect_status(p, 8, PD_ERR_NONFINITE);
    p[5].y = INFINITY;
    expect_status(p, 8, PD_ERR_NONFINITE);
    for (int i = 0; i < 100; i++)
        p[i] = v3(1e6, -3, 0.25);
    expect_status(p, 100, PD_ERR_COLOCATED);
    /* on a line, and on a plane, up to 1e-9 of the size (below 1e-7) */
    for (int i = 0; i < 100; i++) {
        double t = rng_range(&rng, -1, 1);
        p[i] = v3(1 + t, 2 - 3 * t + 1e-9 * rng_uniform(&rng), 2 * t);
    }
    expect_status(p, 100, PD_ERR_COLLINEAR);
    for (int i = 0; i < 100; i++) {
        double s = rng_range(&rng, -1, 1), t = rng_range(&rng, -1, 1);
        p[i] = v3(s, t, 0.3 * s - 0.2 * t + 1e-9 * rng_uniform(&rng));
    }
    expect_status(p, 100, PD_ERR_COPLANAR);
    /* one point above an exact plane: 1e-9 (below the tolerance) is still
     * flat, 1e-6 (above it) is a thin solid, a flat pyramid */
    for (int i = 0; i < 100; i++)
        p[i] = v3(rng_range(&rng, -1, 1), rng_range(&rng, -1, 1), i == 50 ? 1e-9 : 0.0);
    expect_status(p, 100, PD_ERR_COPLANAR);
    p[50].z = 1e-6;
    pd_hull *h = build_checked(p, 100);
    pd_hull_free(h);
    pd_diag d;
    pd_diag_init(&d);
    CHECK_STATUS(pd_hull_build(NULL, 10, &h, &d), PD_ERR_USAGE);
}

static void test_large_and_deterministic(void)
{
    enum { N = 100000 };
    pd_vec3 *p = malloc(sizeof *p * N);
    test_rng rng = {7};
    for (int i = 0; i < N; i++)
        p[i] = rng_unit_vector(&rng);
    pd_hull *a = build_checked(p, N), *b = build_checked(p, N);
    qhull_ref q;
    int rc = qhull_ref_build(p, N, &q);
    CHECK_INT(rc, 0);
    if (a && b && rc == 0) {
        /* At 10^5 points neighbouring triangles are ~4e-5 off one plane, so
         * a few in a hundred come within the 3.5e-7 tolerance and merge
         * (measured: 2.5% fewer facets than the 2N - 4 triangles); a point
         * whose triangles all merged into two facets is dropped (measured:
         * 13). Bounds with a margin of ~4: merges under 10% of the facets,
         * dropped points under 1 in 2000. The hull is still the exact one:
         * pd_hull_check (above) and qhull's volume to 1e-12. */
        CHECK(a->nverts <= N && a->nverts >= N - N / 2000);
        CHECK(a->nfacets <= 2 * N - 4 && a->nfacets >= 2 * N - 4 - N / 5);
        CHECK_REL(a->volume, q.volume, VOLUME_REL, "sum of tetrahedra of the exact triangulation");
        int same = a->nverts == b->nverts && a->nfacets == b->nfacets &&
                   !memcmp(a->verts, b->verts, sizeof *a->verts * (size_t)a->nverts) &&
                   !memcmp(a->normal, b->normal, sizeof *a->normal * (size_t)a->nfacets) &&
                   !memcmp(a->facet_vert, b->facet_vert, sizeof(int) * (size_t)a->facet_start[a->nfacets]) &&
                   !memcmp(a->facet_adj, b->facet_adj, sizeof(int) * (size_t)a->facet_start[a->nfacets]) &&
                   a->volume == b->volume;
        CHECK(same);
    }
    if (rc == 0)
        qhull_ref_free(&q);
    pd_hull_free(a);
    pd_hull_free(b);
    free(p);
}

void suite_hull(void)
{
    test_predicate();
    test_solids();
    test_vs_qhull_random();
    test_vs_qhull_degenerate();
    test_invariance();
    test_merging();
    test_merge_repair();
    test_degenerate_status();
    test_large_and_deterministic();
}
