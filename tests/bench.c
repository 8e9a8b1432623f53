/* bench.c: speed figures for `make bench`.
 *
 * Every figure is a ratio against a reference run in the same process on the
 * same data (qhull's hull of the same points), so it means the same on a slow
 * and a fast machine; absolute times are printed beside them for context only.
 * Nothing here passes or fails. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "posedrop/posedrop.h"
#include "qhull_ref.h"
#include "shapes.h"
#include "vec3.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Best of several runs: the least disturbed by the rest of the machine. */
#define BEST_OF 5

static double time_pd_hull(const pd_vec3 *p, int n, int reps, int *nfacets)
{
    double best = 1e300;
    for (int r = 0; r < BEST_OF; r++) {
        double t0 = now();
        for (int k = 0; k < reps; k++) {
            pd_hull *h = NULL;
            if (pd_hull_build(p, n, &h, NULL) != PD_OK) {
                fprintf(stderr, "bench: pd_hull_build failed\n");
                exit(1);
            }
            *nfacets = h->nfacets;
            pd_hull_free(h);
        }
        double t = (now() - t0) / reps;
        best = t < best ? t : best;
    }
    return best;
}

static double time_qhull(const pd_vec3 *p, int n, int reps, int *nfacets)
{
    double best = 1e300;
    for (int r = 0; r < BEST_OF; r++) {
        double t0 = now();
        for (int k = 0; k < reps; k++) {
            qhull_ref q;
            if (qhull_ref_build(p, n, &q) != 0) {
                fprintf(stderr, "bench: qhull failed\n");
                exit(1);
            }
            *nfacets = q.nfacets;
            qhull_ref_free(&q);
        }
        double t = (now() - t0) / reps;
        best = t < best ? t : best;
    }
    return best;
}

static void points_cube(test_rng *rng, pd_vec3 *p, int n)
{
    for (int i = 0; i < n; i++)
        p[i] = v3(rng_range(rng, -1, 1), rng_range(rng, -1, 1), rng_range(rng, -1, 1));
}

static void points_sphere(test_rng *rng, pd_vec3 *p, int n)
{
    for (int i = 0; i < n; i++)
        p[i] = rng_unit_vector(rng);
}

static void bench_hull(void)
{
    enum { N = 1000000 };
    pd_vec3 *p = malloc(sizeof *p * N);
    test_rng rng = {42};
    printf("\nconvex hull of 10^6 points: posedrop vs qhull (libqhull_r, merged facets), same points\n");
    printf("%-22s %12s %12s %10s %10s\n", "cloud", "posedrop ms", "qhull ms", "facets", "ratio");
    for (int c = 0; c < 2; c++) {
        if (c == 0)
            points_cube(&rng, p, N);
        else
            points_sphere(&rng, p, N);
        int nf_pd = 0, nf_q = 0;
        double t_pd = time_pd_hull(p, N, 1, &nf_pd);
        double t_q = time_qhull(p, N, 1, &nf_q);
        printf("%-22s %12.1f %12.1f %10d %9.2fx%s\n", c == 0 ? "uniform in a cube" : "on a sphere",
               1e3 * t_pd, 1e3 * t_q, nf_pd, t_pd / t_q, nf_pd == nf_q ? "" : "  (facet counts differ!)");
    }
    free(p);
}

static void bench_static(void)
{
    printf("\nQS + PQS on convex parts (random points on an ellipsoid, centre of mass off-centre)\n");
    printf("reference: qhull's hull of the same points, same process\n");
    printf("(build: weld, hull, orientation, mass properties of the part's mesh)\n");
    printf("%-8s %8s %8s %12s %12s %10s %10s %10s %13s\n", "points", "facets", "stable",
           "estimate ms", "build ms", "qhull ms", "est/qhull", "all/qhull", "descent/edge");
    const int sizes[] = {27, 300, 10000};
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; s++) {
        int n = sizes[s];
        test_rng rng = {7 + s};
        pd_vec3 *p = malloc(sizeof *p * (size_t)n);
        for (int i = 0; i < n; i++) {
            pd_vec3 u = rng_unit_vector(&rng);
            p[i] = v3(1.0 * u.x, 0.7 * u.y, 0.45 * u.z);
        }
        pd_hull *h = NULL;
        if (pd_hull_build(p, n, &h, NULL) != PD_OK) {
            fprintf(stderr, "bench: hull failed\n");
            exit(1);
        }
        pd_mesh *m = mesh_of_hull(h);
        pd_hull_free(h);
        pd_part_options po;
        pd_part_options_default(&po);
        po.com_given = 1;
        po.com = v3(0.12, -0.05, 0.03);
        pd_part *part = NULL;
        int build_reps = n < 1000 ? 200 : 3;
        double t_build = 1e300;
        for (int r = 0; r < BEST_OF; r++) {
            double t0 = now();
            for (int k = 0; k < build_reps; k++) {
                pd_part_free(part);
                part = NULL;
                if (pd_part_build(m, &po, &part, NULL) != PD_OK) {
                    fprintf(stderr, "bench: part failed\n");
                    exit(1);
                }
            }
            double t = (now() - t0) / build_reps;
            t_build = t < t_build ? t : t_build;
        }
        int reps = n < 1000 ? 2000 : 20;
        double t_rule[2];
        int nstable = 0;
        for (int rule = 0; rule < 2; rule++) {
            pd_static_options so;
            pd_static_options_default(&so);
            so.topple = rule == 0 ? PD_TOPPLE_DESCENT : PD_TOPPLE_EDGE;
            double best = 1e300;
            for (int r = 0; r < BEST_OF; r++) {
                double t0 = now();
                for (int k = 0; k < reps; k++) {
                    pd_static_result *res = NULL;
                    if (pd_static_estimate(part, &so, &res, NULL) != PD_OK) {
                        fprintf(stderr, "bench: estimate failed\n");
                        exit(1);
                    }
                    nstable = res->nposes;
                    pd_static_result_free(res);
                }
                double t = (now() - t0) / reps;
                best = t < best ? t : best;
            }
            t_rule[rule] = best;
        }
        int nfq;
        double t_q = time_qhull(p, n, n < 1000 ? 200 : 3, &nfq);
        printf("%-8d %8d %8d %12.4f %12.4f %10.4f %9.2fx %9.2fx %12.2fx\n", n,
               part->hull->nfacets, nstable, 1e3 * t_rule[0], 1e3 * t_build, 1e3 * t_q,
               t_rule[0] / t_q, (t_rule[0] + t_build) / t_q, t_rule[0] / t_rule[1]);
        pd_part_free(part);
        pd_mesh_free(m);
        free(p);
    }
}

int main(void)
{
    printf("posedrop %s benchmark (best of %d runs each)\n", PD_VERSION_STRING, BEST_OF);
    bench_static();
    bench_hull();
    return 0;
}
