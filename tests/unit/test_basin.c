/* test_basin.c: energy barriers between basins, and descent from any
 * orientation (the dynamic estimator's test for "the outcome can no longer
 * change"). */
#include <stdlib.h>
#include "settle/basin.h"
#include "check.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "static/static_internal.h"
#include "suites.h"
#include "base/vec3.h"

static pd_static_result *descent_result(const pd_part *p)
{
    pd_static_options o;
    pd_static_options_default(&o);
    o.topple = PD_TOPPLE_DESCENT;
    pd_static_result *r = NULL;
    pd_static_estimate(p, &o, &r, NULL);
    return r;
}

/* Support function: height of the centre of mass above the floor. */
static double support(const pd_part *p, pd_vec3 g)
{
    double m = -1e300;
    for (int v = 0; v < p->hull->nverts; v++)
        m = fmax(m, v3_dot(v3_sub(p->hull->verts[v], p->com), g));
    return m;
}

static void test_box(void)
{
    /* The face normal to axis i rests at height d_i / 2; rolling over an edge
     * towards the face normal to j lifts the centre to sqrt(d_i^2 + d_j^2)/2,
     * the closed form of its barrier (the lower of the two j). */
    const double dims[][3] = {{1, 1, 1}, {1, 2, 3}, {0.3, 1, 0.05}};
    for (int t = 0; t < 3; t++) {
        const double *d = dims[t];
        pd_part *p = part_of(mesh_box(d[0], d[1], d[2]), NULL, NULL);
        pd_static_result *r = p ? descent_result(p) : NULL;
        CHECK(r != NULL);
        if (!r) {
            pd_part_free(p);
            continue;
        }
        double *bar = malloc(sizeof *bar * (size_t)r->nfacets);
        pd_basin_barriers(p->hull, p->com, r, bar);
        for (int f = 0; f < r->nfacets; f++) {
            pd_vec3 n = p->hull->normal[f];
            int i = fabs(n.x) > 0.5 ? 0 : fabs(n.y) > 0.5 ? 1 : 2;
            int j = (i + 1) % 3, k = (i + 2) % 3;
            double want = 0.5 * fmin(hypot(d[i], d[j]), hypot(d[i], d[k]));
            CHECK_REL(bar[f], want, 1e-14, "closed form, round-off");
            CHECK(bar[f] > r->facets[f].height);
        }
        /* One basin only: nothing to cross, the barrier is infinite. */
        for (int f = 0; f < r->nfacets; f++)
            r->facets[f].rest = 0;
        pd_basin_barriers(p->hull, p->com, r, bar);
        int all_inf = 1;
        for (int f = 0; f < r->nfacets; f++)
            all_inf &= isinf(bar[f]) && bar[f] > 0;
        CHECK(all_inf);
        free(bar);
        pd_static_result_free(r);
        pd_part_free(p);
    }
}

/* Numeric steepest descent from g by small projected-subgradient steps: the
 * stable facet it has settled at (within 20 steps of its normal), or -1 if it
 * is still on its way (rolling along an edge, subgradient steps zigzag). */
static int numeric_rest(const pd_part *p, const pd_static_result *r, pd_vec3 g)
{
    const pd_hull *h = p->hull;
    for (int it = 0; it < 40000; it++) {
        int best = 0;
        double hm = -1e300;
        for (int v = 0; v < h->nverts; v++) {
            double x = v3_dot(v3_sub(h->verts[v], p->com), g);
            if (x > hm) {
                hm = x;
                best = v;
            }
        }
        pd_vec3 t = v3_sub(h->verts[best], p->com);
        t = v3_sub(t, v3_scale(g, v3_dot(t, g)));
        g = v3_unit(v3_sub(g, v3_scale(v3_unit(t), 1e-4)));
    }
    for (int f = 0; f < h->nfacets; f++)
        if (r->facets[f].stable && v3_angle(g, h->normal[f]) < 2e-3)
            return f;
    return -1;
}

static void test_random(void)
{
    test_rng rng = {31337};
    int compared = 0, agree = 0, paths = 0, below = 0;
    for (int trial = 0; trial < 4; trial++) {
        pd_part *p = part_random_ellipsoid(&rng, 20, 0.7, 0.5, 0.2, 0.15);
        pd_static_result *r = p ? descent_result(p) : NULL;
        if (!r) {
            pd_part_free(p);
            continue;
        }
        pd_star star;
        CHECK_STATUS(pd_star_build(p->hull, &star), PD_OK);
        double *bar = malloc(sizeof *bar * (size_t)r->nfacets);
        pd_basin_barriers(p->hull, p->com, r, bar);

        /* Descent from random orientations lands where numeric descent does. */
        enum { NS = 40 };
        pd_vec3 g[NS];
        int basin[NS], hint = 0;
        for (int s = 0; s < NS; s++) {
            g[s] = rng_unit_vector(&rng);
            int f = -1;
            CHECK_STATUS(pd_descend(p->hull, &star, p->com, g[s], &f, &hint), PD_OK);
            basin[s] = f >= 0 ? r->facets[f].rest : -1;
            int oracle = numeric_rest(p, r, g[s]);
            if (oracle >= 0 && s < 16) {
                compared++;
                agree += oracle == basin[s];
            }
        }
        /* Any path between two basins climbs at least to the lower of their
         * barriers: sample great circles between points of different basins. */
        for (int s = 0; s + 1 < NS; s++) {
            int t = s + 1;
            if (basin[s] < 0 || basin[t] < 0 || basin[s] == basin[t])
                continue;
            double top = 0.0, ang = v3_angle(g[s], g[t]);
            pd_vec3 axis = v3_unit(v3_cross(g[s], g[t]));
            for (int k = 0; k <= 2000; k++) {
                double a = ang * k / 2000;
                pd_vec3 x = v3_add(v3_scale(g[s], cos(a)),
                                   v3_scale(v3_cross(axis, g[s]), sin(a)));
                top = fmax(top, support(p, x));
            }
            paths++;
            below += top < fmin(bar[basin[s]], bar[basin[t]]) * (1 - 1e-12);
        }
        free(bar);
        pd_star_free(&star);
        pd_static_result_free(r);
        pd_part_free(p);
    }
    CHECK(compared >= 20);
    CHECK_INT(agree, compared);
    CHECK(paths >= 10);
    CHECK_INT(below, 0);
}

void suite_basin(void)
{
    test_box();
    test_random();
}
