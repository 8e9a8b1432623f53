/* predicates.c: the exact fallback of pd_orient3d.
 *
 * The determinant (b-a) x (c-a) . (d-a) expands, by multilinearity, into
 * [b,c,d] - [a,b,c] + [a,b,d] - [a,c,d] with [p,q,r] = p . (q x r): 24
 * signed products of three input coordinates and no subtraction of inputs,
 * so nothing is rounded before the products. Each product of three doubles is
 * split exactly into four doubles (two error-free products with fma), and the
 * 96 doubles are summed into a nonoverlapping expansion by error-free
 * additions. The sign of an expansion is the sign of its largest component.
 * Exact as long as no product overflows or underflows. */
#include <math.h>
#include "base/predicates.h"

/* s + e == a + b exactly, |e| <= ulp(s) / 2 (Knuth's branch-free two-sum). */
static void two_sum(double a, double b, double *s, double *e)
{
    double x = a + b;
    double bv = x - a;
    double av = x - bv;
    *e = (a - av) + (b - bv);
    *s = x;
}

/* p + e == a * b exactly: fma rounds a * b - p once, and that value is
 * representable, so the rounding is exact. */
static void two_prod(double a, double b, double *p, double *e)
{
    double x = a * b;
    *e = fma(a, b, -x);
    *p = x;
}

/* Longest expansion: 96 inputs, and a nonoverlapping expansion of doubles has
 * at most one component per 53-bit stretch of the exponent range (~2100 bits
 * / 53 < 45), so 128 is more than enough. */
#define EXP_MAX 128

typedef struct {
    int n;
    double c[EXP_MAX]; /* increasing magnitude, nonoverlapping, no zeros */
} expansion;

/* e += b, exactly (grow-expansion with zero elimination). */
static void exp_add(expansion *e, double b)
{
    if (b == 0.0)
        return;
    double q = b;
    int k = 0;
    for (int i = 0; i < e->n; i++) {
        double s, err;
        two_sum(q, e->c[i], &s, &err);
        q = s;
        if (err != 0.0)
            e->c[k++] = err;
    }
    if (q != 0.0 && k < EXP_MAX)
        e->c[k++] = q;
    e->n = k;
}

/* e += sign * x * y * z, exactly. */
static void exp_add_prod3(expansion *e, double sign, double x, double y, double z)
{
    double p, pe, p1, e1, p2, e2;
    two_prod(sign * x, y, &p, &pe);
    two_prod(p, z, &p1, &e1);
    two_prod(pe, z, &p2, &e2);
    exp_add(e, e2);
    exp_add(e, e1);
    exp_add(e, p2);
    exp_add(e, p1);
}

/* e += sign * [p, q, r] = sign * p . (q x r). */
static void exp_add_triple(expansion *e, double sign, const pd_vec3 *p, const pd_vec3 *q, const pd_vec3 *r)
{
    exp_add_prod3(e, sign, p->x, q->y, r->z);
    exp_add_prod3(e, -sign, p->x, q->z, r->y);
    exp_add_prod3(e, sign, p->y, q->z, r->x);
    exp_add_prod3(e, -sign, p->y, q->x, r->z);
    exp_add_prod3(e, sign, p->z, q->x, r->y);
    exp_add_prod3(e, -sign, p->z, q->y, r->x);
}

/* The differences b - a, c - a, d - a when all nine are exact (a rounded
 * difference is exact when its error-free remainder is zero; by Sterbenz's
 * lemma always so for coordinates within a factor of two of each other, the
 * usual case of near neighbours far from the origin's planes). 0 when one
 * is not, or is of a scale whose products of three could leave the range
 * of normal doubles. */
static int exact_differences(const pd_vec3 *a, const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d,
                             double u[3][3])
{
    const pd_vec3 *p[3] = {b, c, d};
    for (int i = 0; i < 3; i++) {
        double x[3] = {p[i]->x - a->x, p[i]->y - a->y, p[i]->z - a->z};
        double in[3] = {p[i]->x, p[i]->y, p[i]->z}, o[3] = {a->x, a->y, a->z};
        for (int k = 0; k < 3; k++) {
            double s, err;
            two_sum(in[k], -o[k], &s, &err);
            /* Products of differences far below or above the inputs'
             * own could underflow or overflow where those of the inputs
             * do not: such scales take the full expansion. */
            double ax = fabs(x[k]);
            if (err != 0.0 || (ax != 0.0 && (ax < 0x1p-250 || ax > 0x1p250)))
                return 0;
            u[i][k] = x[k];
        }
    }
    return 1;
}

static int expansion_sign(const expansion *e)
{
    if (e->n == 0)
        return 0;
    double top = e->c[e->n - 1];
    return (top > 0.0) - (top < 0.0);
}

int pd_orient3d_exact(const pd_vec3 *a, const pd_vec3 *b, const pd_vec3 *c, const pd_vec3 *d)
{
    expansion e;
    e.n = 0;
    /* A first stage: with the differences exact, the determinant of u, v, w
     * is 6 products of three (24 doubles), not the 24 of the inputs (96
     * doubles). Near-coplanar neighbours of a mesh turned off the axes reach
     * the fallback by the million, and almost all have exact differences. */
    double u[3][3];
    if (exact_differences(a, b, c, d, u)) {
        pd_vec3 U = {u[0][0], u[0][1], u[0][2]}, V = {u[1][0], u[1][1], u[1][2]},
                W = {u[2][0], u[2][1], u[2][2]};
        exp_add_triple(&e, 1.0, &U, &V, &W);
        return expansion_sign(&e);
    }
    exp_add_triple(&e, 1.0, b, c, d);
    exp_add_triple(&e, -1.0, a, b, c);
    exp_add_triple(&e, 1.0, a, b, d);
    exp_add_triple(&e, -1.0, a, c, d);
    return expansion_sign(&e);
}
