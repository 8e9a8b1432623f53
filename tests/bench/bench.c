/* bench.c: speed figures for `make bench`.
 *
 * Every figure is a ratio against a reference run in the same process on the
 * same data (qhull's hull of the same points; for the drops, the plain scene
 * and the one-thread run), so it means the same on a slow and a fast machine;
 * absolute times are printed beside them for context only. The drops' cost is
 * also set against the issue's fixed target of 50 us per drop. Nothing here
 * passes or fails. `bench_posedrop static hull dynamic engines batch` runs
 * only the parts named. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/resource.h>
#include <unistd.h>
#include "cli_paths.h"
#include "sim/drop.h"
#include "posedrop/posedrop.h"
#include "posedrop/sim.h"
#include "qhull_ref.h"
#include "shapes.h"
#include "symmetry/symmetry_search.h"
#include "base/vec3.h"

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Best of several runs: the least disturbed by the rest of the machine. */
#define BEST_OF 5

/* A failing build is reported (diag->message) and timed no further: returns
 * a negative time. */
static double time_pd_hull(const pd_vec3 *p, int n, int reps, int *nfacets, pd_diag *diag)
{
    double best = 1e300;
    for (int r = 0; r < BEST_OF; r++) {
        double t0 = now();
        for (int k = 0; k < reps; k++) {
            pd_hull *h = NULL;
            if (pd_hull_build(p, n, &h, diag) != PD_OK)
                return -1.0;
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

static void time_qhull_once(const pd_vec3 *p, int n, int *nfacets)
{
    qhull_ref q;
    if (qhull_ref_build(p, n, &q) != 0) {
        fprintf(stderr, "bench: qhull failed\n");
        exit(1);
    }
    *nfacets = q.nfacets;
    qhull_ref_free(&q);
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
        pd_diag diag;
        pd_diag_init(&diag);
        double t_pd = time_pd_hull(p, N, 1, &nf_pd, &diag);
        double t_q = time_qhull(p, N, 1, &nf_q);
        if (t_pd < 0) {
            printf("%-22s %12s %12.1f %10d   pd_hull_build FAILED: %s\n",
                   c == 0 ? "uniform in a cube" : "on a sphere", "-", 1e3 * t_q, nf_q, diag.message);
            continue;
        }
        /* The counts may differ: posedrop merges facets within PD_TOL_PLANE_REL
         * of one plane, qhull by its own merge criteria. */
        printf("%-22s %12.1f %12.1f %10d %9.2fx", c == 0 ? "uniform in a cube" : "on a sphere",
               1e3 * t_pd, 1e3 * t_q, nf_pd, t_pd / t_q);
        if (nf_pd != nf_q)
            printf("  (qhull: %d facets, merged by its own criteria)", nf_q);
        printf("\n");
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

/* The noisy latitude-longitude sphere of scripts/make-big-meshes.py
 * (m x m vertices and two poles at random radii in [0.5, 1], 2 m^2
 * triangles): closed, star-shaped, many long thin triangles. */
static pd_mesh *latlong_mesh(int m, test_rng *rng)
{
    pd_mesh *me = malloc(sizeof *me);
    int nv = m * m + 2, nt = 2 * m * m, t = 0;
    me->nverts = nv;
    me->ntris = nt;
    me->verts = malloc(sizeof *me->verts * (size_t)nv);
    me->tris = malloc(sizeof *me->tris * (size_t)nt);
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double th = M_PI * (i + 1) / (m + 1), ph = 2.0 * M_PI * j / m;
            double r = 0.5 + 0.5 * rng_uniform(rng);
            me->verts[i * m + j] = v3(r * sin(th) * cos(ph), r * sin(th) * sin(ph), r * cos(th));
        }
    me->verts[m * m] = v3(0, 0, 0.5 + 0.5 * rng_uniform(rng));
    me->verts[m * m + 1] = v3(0, 0, -(0.5 + 0.5 * rng_uniform(rng)));
    for (int j = 0; j < m; j++) {
        int jn = (j + 1) % m, a = (m - 1) * m;
        int cap[2][3] = {{m * m, j, jn}, {m * m + 1, a + jn, a + j}};
        for (int c = 0; c < 2; c++, t++)
            for (int k = 0; k < 3; k++)
                me->tris[t][k] = cap[c][k];
        for (int i = 0; i + 1 < m; i++) {
            int p = i * m, q = (i + 1) * m;
            int quad[2][3] = {{p + j, q + j, q + jn}, {p + j, q + jn, p + jn}};
            for (int c = 0; c < 2; c++, t++)
                for (int k = 0; k < 3; k++)
                    me->tris[t][k] = quad[c][k];
        }
    }
    return me;
}

/* Two such spheres, the second after the first in the random stream and
 * moved 2.5 along x (make-big-meshes.py pair): apart, and not star-shaped,
 * so the self-crossing check runs its search. */
static pd_mesh *latlong_pair(int m, test_rng *rng)
{
    pd_mesh *a = latlong_mesh(m, rng), *b = latlong_mesh(m, rng);
    int nv = a->nverts, nt = a->ntris;
    a->verts = realloc(a->verts, sizeof *a->verts * 2 * (size_t)nv);
    a->tris = realloc(a->tris, sizeof *a->tris * 2 * (size_t)nt);
    for (int i = 0; i < nv; i++)
        a->verts[nv + i] = v3_add(b->verts[i], v3(2.5, 0, 0));
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            a->tris[nt + t][k] = b->tris[t][k] + nv;
    a->nverts = 2 * nv;
    a->ntris = 2 * nt;
    pd_mesh_free(b);
    return a;
}

/* The whole static pipeline of a large noisy scan (part build: weld, hull,
 * orientation, mass properties, self-crossing check; then QS and PQS)
 * against qhull's hull of the same vertices, one run each: a regression in
 * any stage that grows faster than the hull shows here as a ratio. One
 * sphere is star-shaped (the check settles it before its search); the
 * pair measures the search. */
static void bench_big_mesh(void)
{
    printf("\nstatic pipeline of a noisy latitude-longitude sphere (scripts/make-big-meshes.py)\n");
    printf("reference: qhull's hull of the same vertices, same process; CPU seconds\n");
    printf("%-10s %6s %10s %10s %10s %10s %12s\n", "triangles", "mesh", "build s", "estimate s",
           "qhull s", "all/qhull", "check");
    const int ms[] = {300, 1000, 707};
    for (size_t s = 0; s < sizeof ms / sizeof ms[0]; s++) {
        test_rng rng = {20261207};
        int pair = s == 2;
        pd_mesh *m = pair ? latlong_pair(ms[s], &rng) : latlong_mesh(ms[s], &rng);
        pd_part_options po;
        pd_part_options_default(&po);
        po.com_given = 1;
        pd_part *part = NULL;
        pd_diag d;
        pd_diag_init(&d);
        double t0 = cpu_now();
        if (pd_part_build(m, &po, &part, &d) != PD_OK) {
            fprintf(stderr, "bench: part failed: %s\n", d.message);
            exit(1);
        }
        double t1 = cpu_now();
        pd_static_result *res = NULL;
        if (pd_static_estimate(part, NULL, &res, NULL) != PD_OK) {
            fprintf(stderr, "bench: estimate failed\n");
            exit(1);
        }
        double t2 = cpu_now();
        int nfq;
        double tq0 = cpu_now();
        time_qhull_once(m->verts, m->nverts, &nfq);
        double tq = cpu_now() - tq0;
        printf("%-10d %6s %10.3f %10.3f %10.3f %9.2fx %12s\n", m->ntris, pair ? "pair" : "one",
               t1 - t0, t2 - t1, tq, (t2 - t0) / tq, part->mass_known ? "solid" : "refused");
        pd_static_result_free(res);
        pd_part_free(part);
        pd_mesh_free(m);
    }
}

/* Best of several calls of pd_symmetry_find_by on part, in seconds; the
 * rotations found go to *nrot. */
static double time_symmetry(const pd_part *part, pd_symmetry_method method, int best_of, int *nrot)
{
    double best = 1e300;
    for (int r = 0; r < best_of; r++) {
        pd_symmetry *s = NULL;
        double t0 = now();
        if (pd_symmetry_find_by(part, method, &s, NULL) != PD_OK) {
            fprintf(stderr, "bench: symmetry search failed\n");
            exit(1);
        }
        double t = now() - t0;
        best = t < best ? t : best;
        *nrot = s->nrotations;
        pd_symmetry_free(s);
    }
    return best;
}

/* The symmetry search (--group) on bodies of revolution, against the
 * exhaustive search it replaced (kept in the library for the tests), which
 * checks every rotation vertex by vertex: O(n^2) in the vertices. */
static void bench_symmetry(void)
{
    printf("\nsymmetry search (pd_symmetry_find) on n-gon prisms and pyramids\n");
    printf("reference: the exhaustive search on the same part, same process\n");
    printf("%-24s %8s %10s %12s %14s %10s %12s\n", "part", "vertices", "rotations",
           "search ms", "exhaustive ms", "exh/search", "build ms");
    const struct {
        const char *name;
        ring_spec r;
    } parts[] = {
        {"500-gon prism", {500, 0, 0.0, 0.0, 0.0, 0, 0}},
        {"1000-gon prism", {1000, 0, 0.0, 0.0, 0.0, 0, 0}},
        {"2000-gon prism", {2000, 0, 0.0, 0.0, 0.0, 0, 0}},
        {"2000-gon prism, float32", {2000, 0, 0.0, 0.0, 0.0, 0, 1}},
        {"2000-gon pyramid", {2000, 1, 0.0, 0.0, 0.0, 0, 0}},
    };
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
        double t0 = now();
        pd_part *part = ring_part(&parts[i].r, NULL, 1.0, v3(0, 0, 0));
        double t_build = now() - t0;
        if (!part) {
            fprintf(stderr, "bench: part failed\n");
            exit(1);
        }
        int nrot = 0, nrot_exh = 0;
        double t_gen = time_symmetry(part, PD_SYMMETRY_GENERATED, BEST_OF, &nrot);
        /* The reference takes seconds at 4000 vertices: best of 2. */
        double t_exh = time_symmetry(part, PD_SYMMETRY_EXHAUSTIVE, 2, &nrot_exh);
        printf("%-24s %8d %10d %12.2f %14.2f %9.1fx %12.2f%s\n", parts[i].name,
               part->hull->nverts, nrot, 1e3 * t_gen, 1e3 * t_exh, t_exh / t_gen, 1e3 * t_build,
               nrot == nrot_exh ? "" : "  (rotation counts differ!)");
        pd_part_free(part);
    }
}

/* --- the dynamic estimator ------------------------------------------------------ *
 * Drops of small parts in the paper's scene (pd_scene_default: 0.12 m, belt,
 * friction, vibration). The reference for the per-drop cost is the issue's
 * target of 50 us per drop; for the scene's effects, the plain scene; for the
 * threads, one thread. Drop counts keep this part under about a minute on two
 * cores. */

enum { DYN_DROPS = 400 };       /* per timed run */
/* The drops are the same in every repeat (seeded), so repeats only filter
 * out the rest of the machine: fewer than BEST_OF keep this part short. */
enum { DYN_BEST_OF = 3 };
#define DROP_TARGET_US 50.0

typedef struct dyn_part {
    const char *name;
    pd_part *part;
    pd_static_result *poses;
} dyn_part;

static dyn_part dyn_part_make(const char *name, pd_mesh *m)
{
    dyn_part d = {name, NULL, NULL};
    if (!m || pd_part_build(m, NULL, &d.part, NULL) != PD_OK ||
        pd_static_estimate(d.part, NULL, &d.poses, NULL) != PD_OK) {
        fprintf(stderr, "bench: cannot build the part %s\n", name);
        exit(1);
    }
    pd_mesh_free(m);
    return d;
}

static void dyn_part_free(dyn_part *d)
{
    pd_static_result_free(d->poses);
    pd_part_free(d->part);
}

static pd_sim_result *sim_run(const dyn_part *d, const pd_scene *sc, long n, int threads,
                              int keep_trials)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = n;
    o.threads = threads;
    o.keep_trials = keep_trials;
    pd_sim_result *r = NULL;
    if (pd_sim_run(d->part, d->poses, sc, &o, &r, NULL) != PD_OK) {
        fprintf(stderr, "bench: pd_sim_run failed on %s\n", d->name);
        exit(1);
    }
    return r;
}

/* Mean wall seconds per drop of pd_sim_run (model build included), best of
 * DYN_BEST_OF runs; *cpu gets that run's process CPU seconds per drop (all
 * threads), *last the last run's result. */
static double time_sim(const dyn_part *d, const pd_scene *sc, long n, int threads,
                       int keep_trials, pd_sim_result **last, double *cpu)
{
    double best = 1e300;
    for (int r = 0; r < DYN_BEST_OF; r++) {
        pd_sim_result_free(*last);
        double c0 = cpu_now(), t0 = now();
        *last = sim_run(d, sc, n, threads, keep_trials);
        double t = (now() - t0) / (double)n, c = (cpu_now() - c0) / (double)n;
        if (t < best) {
            best = t;
            if (cpu)
                *cpu = c;
        }
    }
    return best;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

typedef struct drop_times {
    double median, p90, max; /* s */
} drop_times;

/* Seconds of one drop: drops 0..n-1 of the run (seed 1, the same drops as
 * pd_sim_run's), each timed alone through the internal drop API (drop.h),
 * the model built once outside. Each drop's time is its least over
 * DROP_REPEATS passes: a drop does the same work every pass, so the least
 * is the one that the machine's other work (a timer tick, another process
 * on the core) interrupted least; one pass moved the median by up to 25%
 * from run to run on this project's 2-core virtual machine. */
enum { DROP_REPEATS = 3 };

static drop_times single_drops(const dyn_part *d, const pd_scene *sc, long n)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    pd_sim_model *model = NULL;
    pd_drop_work *w = NULL;
    if (pd_sim_model_build(d->part, d->poses, sc, &o, &model, NULL) != PD_OK ||
        !(w = pd_drop_work_alloc(model, sc))) {
        fprintf(stderr, "bench: no drop model for %s\n", d->name);
        exit(1);
    }
    double *t = malloc(sizeof *t * (size_t)n);
    long gain = 0, fallbacks = 0;
    for (int pass = 0; pass < DROP_REPEATS; pass++)
        for (long i = 0; i < n; i++) {
            pd_trial out;
            double t0 = now();
            pd_drop_run(model, w, sc, &o, i, NULL, &out, &gain, &fallbacks);
            double ti = now() - t0;
            t[i] = pass == 0 || ti < t[i] ? ti : t[i];
        }
    qsort(t, (size_t)n, sizeof *t, cmp_double);
    drop_times dt = {n % 2 ? t[n / 2] : 0.5 * (t[n / 2 - 1] + t[n / 2]), t[(9 * n) / 10],
                     t[n - 1]};
    free(t);
    pd_drop_work_free(w);
    pd_sim_model_free(model);
    return dt;
}

static void bench_drop_cost(dyn_part *parts, int nparts)
{
    pd_scene sc;
    pd_scene_default(&sc);
    printf("\ndynamic estimator, one thread: cost per drop, paper's scene (pd_scene_default, %.2f m)\n",
           sc.height);
    printf("median: %d drops each timed alone through pd_drop_run (drop.h), model built outside,\n"
           "each drop's least time over %d passes\n",
           DYN_DROPS, DROP_REPEATS);
    printf("mean: pd_sim_run, threads = 1, the same %d drops, total / n (model build included),\n"
           "best of %d; drops/s = 1 / mean\n", DYN_DROPS, DYN_BEST_OF);
    printf("reference: the early goal of %.0f us per drop\n", DROP_TARGET_US);
    printf("%-16s %5s %9s %9s %9s %9s %8s %9s %6s  %s\n", "part", "poses", "median us", "p90 us",
           "max us", "mean us", "drops/s", "coll/drop", "unset", "vs target (median; mean)");
    for (int k = 0; k < nparts; k++) {
        const dyn_part *d = &parts[k];
        drop_times dt = single_drops(d, &sc, DYN_DROPS);
        pd_sim_result *r = NULL;
        double mean = time_sim(d, &sc, DYN_DROPS, 1, 0, &r, NULL);
        printf("%-16s %5d %9.1f %9.1f %9.0f %9.1f %8.0f %9.1f %6ld  %.2fx; %.2fx of the %.0f us target\n",
               d->name, d->poses->nposes, 1e6 * dt.median, 1e6 * dt.p90, 1e6 * dt.max, 1e6 * mean,
               1.0 / mean, (double)r->collisions / (double)r->n, r->unsettled,
               1e6 * dt.median / DROP_TARGET_US, 1e6 * mean / DROP_TARGET_US, DROP_TARGET_US);
        pd_sim_result_free(r);
    }
}

static void bench_effects(const dyn_part *d)
{
    pd_scene plain;
    pd_scene_default(&plain);
    plain.mu = 0.0;
    plain.vibration = 0.0;
    plain.belt_speed = 0.0;
    plain.initial = PD_INITIAL_UNIFORM;
    printf("\nsimulate only the effects a scene calls for: %s, one thread, %d drops, best of %d\n",
           d->name, DYN_DROPS, DYN_BEST_OF);
    printf("reference: the plain scene (mu 0, vibration 0, belt 0, uniform initial), same process\n");
    printf("%-28s %10s %9s %9s %10s\n", "scene", "mean us", "coll/drop", "unsettled", "ratio");
    double t_ref = 0.0;
    for (int e = 0; e < 6; e++) {
        pd_scene sc = plain;
        const char *name = "plain (reference)";
        if (e == 1 || e == 5) {
            sc.mu = 0.3;
            name = "mu 0.3";
        }
        if (e == 2 || e == 5) {
            sc.vibration = 1.5 * M_PI / 180.0;
            name = "vibration 1.5 deg";
        }
        if (e == 3 || e == 5) {
            sc.belt_speed = 0.05;
            name = "belt 0.05 m/s";
        }
        if (e == 4 || e == 5) {
            sc.initial = PD_INITIAL_BOOTSTRAP;
            name = "bootstrap initial";
        }
        if (e == 5)
            name = "all together";
        pd_sim_result *r = NULL;
        double t = time_sim(d, &sc, DYN_DROPS, 1, 0, &r, NULL);
        if (e == 0)
            t_ref = t;
        printf("%-28s %10.1f %9.1f %9ld %9.2fx\n", name, 1e6 * t,
               (double)r->collisions / (double)r->n, r->unsettled, t / t_ref);
        pd_sim_result_free(r);
    }
}

/* What ranges cost: every parameter given as a range of zero width runs the
 * fixed scene's very drops (tested), so its time against the fixed run's is
 * the cost of drawing the values and setting each drop's contact law; plain
 * ranges change the drops themselves (their collisions are shown), so their
 * ratio is the physics of the range, not its overhead. */
static void bench_ranges(dyn_part *parts, int nparts)
{
    printf("\nranges: cost per drop against the same scene with fixed values, one thread, %d "
           "drops, best of %d\n", DYN_DROPS, DYN_BEST_OF);
    printf("%-16s %-26s %10s %9s %9s\n", "part", "scene", "mean us", "coll/drop", "ratio");
    static const char *const zero[][2] = {{"height", "0.12:0.12"}, {"belt_speed", "0.05:0.05"},
                                          {"mu", "0.3:0.3"}, {"restitution", "0.3:0.3"},
                                          {"vibration", "1.5:1.5"}, {"contact_time", "1x:1x"},
                                          {"tumble", "0:0"}};
    static const char *const wide[][2] = {{"height", "0.08:0.16"}, {"mu", "0.2:0.6"},
                                          {"restitution", "0.1:0.5"}, {"contact_time", "0.3x:3x"}};
    for (int k = 0; k < nparts; k++) {
        pd_scene fixed, z, w;
        pd_scene_default(&fixed);
        pd_scene_set(&fixed, "vibration", "1.5", NULL);
        z = w = fixed;
        for (int i = 0; i < 7; i++)
            pd_scene_set(&z, zero[i][0], zero[i][1], NULL);
        for (int i = 0; i < 4; i++)
            pd_scene_set(&w, wide[i][0], wide[i][1], NULL);
        if (k == 0) {
            /* The draw alone, many times over: what a range adds to a drop
             * besides its contact law (a few multiplications, table look-ups). */
            enum { DRAWS = 1000000 };
            double v[PD_NPARAMS], sink = 0.0, t0 = now();
            for (long i = 0; i < DRAWS; i++) {
                pd_scene_draw(&w, 0.017, 1, i, v, NULL);
                sink += v[PD_PARAM_MU];
            }
            printf("drawing one drop's values (pd_scene_draw): %.3f us (mean of %d; mean mu %.3f)\n",
                   1e6 * (now() - t0) / DRAWS, DRAWS, sink / DRAWS);
        }
        const pd_scene *sc[3] = {&fixed, &z, &w};
        const char *name[3] = {"fixed values (reference)", "every value a 0-width range",
                               "mu, e, height, contact time"};
        double t_ref = 0.0;
        for (int e = 0; e < 3; e++) {
            pd_sim_result *r = NULL;
            double t = time_sim(&parts[k], sc[e], DYN_DROPS, 1, 0, &r, NULL);
            if (e == 0)
                t_ref = t;
            printf("%-16s %-26s %10.1f %9.1f %8.3fx\n", e ? "" : parts[k].name, name[e], 1e6 * t,
                   (double)r->collisions / (double)r->n, t / t_ref);
            pd_sim_result_free(r);
        }
    }
}

/* Same outcome, drop by drop: counts and every trial record's fields. */
static int same_result(const pd_sim_result *a, const pd_sim_result *b)
{
    if (a->n != b->n || a->nposes != b->nposes || a->unsettled != b->unsettled ||
        a->collisions != b->collisions || a->energy_gain != b->energy_gain ||
        a->fallbacks != b->fallbacks)
        return 0;
    for (int k = 0; k < a->nposes; k++)
        if (a->count[k] != b->count[k])
            return 0;
    for (long i = 0; i < a->n; i++) {
        const pd_trial *x = &a->trials[i], *y = &b->trials[i];
        if (memcmp(x->q0, y->q0, sizeof x->q0) != 0 || x->pose != y->pose ||
            x->collisions != y->collisions || x->time != y->time || x->end != y->end)
            return 0;
    }
    return 1;
}

static void bench_threads(const dyn_part *d)
{
    enum { N = 2 * DYN_DROPS };
    pd_scene sc;
    pd_scene_default(&sc);
    printf("\nparallel speed-up: %s, paper's scene, %d drops, best of %d\n", d->name, N, DYN_BEST_OF);
    printf("reference: the same run on one thread, same process\n");
    printf("(cpu/wall: cores the process actually got; below the thread count, the machine is busy)\n");
    printf("%-8s %10s %10s %10s %9s %9s\n", "threads", "wall ms", "cpu ms", "mean us", "cpu/wall",
           "speed-up");
    double t1 = 0.0;
    pd_sim_result *r[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        double cpu = 0.0, t = time_sim(d, &sc, N, k + 1, 1, &r[k], &cpu);
        if (k == 0)
            t1 = t;
        printf("%-8d %10.1f %10.1f %10.1f %9.2f %8.2fx\n", k + 1, 1e3 * t * N, 1e3 * cpu * N,
               1e6 * t, cpu / t, t1 / t);
    }
    printf("determinism, threads 1 vs 2 (counts, collisions, every trial record): %s\n",
           same_result(r[0], r[1]) ? "identical" : "DIFFERENT");
    pd_sim_result_free(r[0]);
    pd_sim_result_free(r[1]);
}

/* The issues' parts: a 1 cm cube, a 1 x 2 x 3 cm box, a thick coin, and the
 * shipped cap (a many-faced part that lands on faces). */
enum { NDYN = 4 };
static void issue_parts(dyn_part parts[NDYN])
{
    parts[0] = dyn_part_make("cube 1 cm", mesh_box(0.01, 0.01, 0.01));
    parts[1] = dyn_part_make("box 1 x 2 x 3 cm", mesh_box(0.01, 0.02, 0.03));
    parts[2] = dyn_part_make("coin 32-gon", mesh_prism(32, 0.01, 0.01));
    pd_mesh *cap = NULL;
    if (pd_mesh_read("parts/cap.off", NULL, &cap, NULL) != PD_OK)
        cap = NULL; /* dyn_part_make reports it */
    parts[3] = dyn_part_make("cap (parts/)", cap);
}

static void bench_dynamic(void)
{
    dyn_part parts[NDYN];
    issue_parts(parts);
    double t0 = now();
    bench_drop_cost(parts, NDYN);
    bench_effects(&parts[1]);
    bench_threads(&parts[1]);
    printf("(dynamic part: %.1f s)\n", now() - t0);
    for (int k = 0; k < NDYN; k++)
        dyn_part_free(&parts[k]);
}

/* --- the engines ----------------------------------------------------------------- *
 * The issue's last paragraph: ms per drop of each engine on the same parts
 * (reference: the impulse engine on that part, same process), and how the
 * distribution moves when the stepping engines' dt is divided by 4. */

enum { ENG_DROPS = 300, CONV_DROPS = 600 };
static const char *const eng_name[] = {"impulse", "ode", "bullet"};
static const double eng_dt[] = {0.0, 1e-3, 1.0 / 960.0}; /* drop.c's defaults */

/* One run of engine e at step dt (0: its default), seed 1; *wall and *cpu get
 * seconds per drop. */
static pd_sim_result *eng_run(const dyn_part *d, int e, double dt, long n, int threads,
                              double *wall, double *cpu)
{
    pd_scene sc;
    pd_scene_default(&sc);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = (pd_engine_kind)e;
    o.dt = dt;
    o.ndrops = n;
    o.seed = 1;
    o.threads = threads;
    o.keep_trials = 1;
    pd_sim_result *r = NULL;
    pd_diag diag;
    pd_diag_init(&diag);
    double c0 = cpu_now(), t0 = now();
    if (pd_sim_run(d->part, d->poses, &sc, &o, &r, &diag) != PD_OK) {
        fprintf(stderr, "bench: %s on %s failed: %s\n", eng_name[e], d->name, diag.message);
        exit(1);
    }
    *wall = (now() - t0) / (double)n;
    *cpu = (cpu_now() - c0) / (double)n;
    return r;
}

static double half_width(const pd_sim_result *r, int k)
{
    return fmax(r->ci_hi[k] - r->p[k], r->p[k] - r->ci_lo[k]);
}

static void bench_engine_cost(dyn_part *parts, int nparts)
{
    printf("\nengines, one thread: ms per drop, paper's scene, %d drops, seed 1, best of %d\n",
           ENG_DROPS, DYN_BEST_OF);
    printf("reference: the impulse engine on the same part, same process "
           "(ode dt %g s, bullet dt 1/960 s)\n", eng_dt[1]);
    printf("%-16s %-8s %10s %9s %10s\n", "part", "engine", "ms/drop", "unsettled", "vs impulse");
    for (int k = 0; k < nparts; k++) {
        double t_ref = 0.0;
        for (int e = 0; e < 3; e++) {
            double t = 1e300, w, cpu;
            pd_sim_result *r = NULL;
            for (int rep = 0; rep < DYN_BEST_OF; rep++) {
                pd_sim_result_free(r);
                r = eng_run(&parts[k], e, 0.0, ENG_DROPS, 1, &w, &cpu);
                t = w < t ? w : t;
            }
            t_ref = e == 0 ? t : t_ref;
            printf("%-16s %-8s %10.3f %9ld %9.2fx\n", e == 0 ? parts[k].name : "",
                   eng_name[e], 1e3 * t, r->unsettled, t / t_ref);
            pd_sim_result_free(r);
        }
    }
}

/* Same seed and drops at dt and dt/4 (two threads: outcomes do not depend on
 * them; the cost ratio is of process CPU time). A pose "moved" if |p(dt/4) -
 * p(dt)| exceeds the larger 95% half-width of the two runs. */
static void bench_engine_dt(const dyn_part *d)
{
    printf("\nconvergence in dt: %s, paper's scene, %d drops, seed 1, dt vs dt/4\n", d->name,
           CONV_DROPS);
    printf("half: the larger 95%% half-width (Wilson, either side) of the two runs\n");
    for (int e = 1; e < 3; e++) {
        double w[2], c[2];
        pd_sim_result *r[2];
        for (int j = 0; j < 2; j++)
            r[j] = eng_run(d, e, j ? eng_dt[e] / 4 : 0.0, CONV_DROPS, 2, &w[j], &c[j]);
        printf("%s: dt %.4g s vs %.4g s (unsettled %ld, %ld)\n", eng_name[e], eng_dt[e],
               eng_dt[e] / 4, r[0]->unsettled, r[1]->unsettled);
        printf("  %4s %8s %8s %8s %8s\n", "pose", "p(dt)", "p(dt/4)", "diff", "half");
        double tv = 0.0, worst = 0.0, worst_h = 0.0;
        int bad = -1;
        for (int k = 0; k < d->poses->nposes; k++) {
            double diff = r[1]->p[k] - r[0]->p[k], h = fmax(half_width(r[0], k), half_width(r[1], k));
            tv += 0.5 * fabs(diff);
            printf("  %4d %8.4f %8.4f %+8.4f %8.4f%s\n", k, r[0]->p[k], r[1]->p[k], diff, h,
                   fabs(diff) > h ? "  moved" : "");
            if (fabs(diff) > h && fabs(diff) - h > worst - worst_h) {
                bad = k;
                worst = fabs(diff);
                worst_h = h;
            }
        }
        long changed = 0;
        for (long i = 0; i < r[0]->n; i++)
            changed += r[0]->trials[i].pose != r[1]->trials[i].pose;
        printf("  total variation %.4f; drops ending elsewhere %ld of %ld; cost dt/4 vs dt %.2fx "
               "(cpu %.2f vs %.2f ms/drop)\n", tv, changed, r[0]->n, c[1] / c[0], 1e3 * c[1],
               1e3 * c[0]);
        if (bad < 0)
            printf("  %s: converged (every pose moved less than its interval)\n", eng_name[e]);
        else
            printf("  %s: NOT converged: pose %d moved by %.4f, more than its interval %.4f\n",
                   eng_name[e], bad, worst, worst_h);
        pd_sim_result_free(r[0]);
        pd_sim_result_free(r[1]);
    }
}

static void bench_engines(void)
{
    dyn_part parts[NDYN];
    issue_parts(parts);
    double t0 = now();
    bench_engine_cost(parts, NDYN);
    bench_engine_dt(&parts[1]);
    printf("(engines part: %.1f s)\n", now() - t0);
    for (int k = 0; k < NDYN; k++)
        dyn_part_free(&parts[k]);
}

/* --- batches ------------------------------------------------------------------- *
 * The command as a batch runs it, whole processes (part read, estimate,
 * drops, output): -j 2 and, when built, posedrop-mpi on two ranks against
 * -j 1, each checked to print the -j 1 run's bytes. */

#define BATCH_PART "parts/cap.off"
enum { BATCH_DROPS = 2000 };

/* CPU seconds of the children waited for so far (the command's processes,
 * mpirun's ranks included). */
static double children_cpu(void)
{
    struct rusage u;
    getrusage(RUSAGE_CHILDREN, &u);
    return (double)(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
           1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/* Best wall time of a shell command writing to out, and the CPU time of that
 * run in *cpu; -1 if it failed. */
static double time_command(const char *cmd, const char *out, double *cpu)
{
    char line[1024];
    snprintf(line, sizeof line, "%s >%s", cmd, out);
    double best = -1.0;
    for (int r = 0; r < BEST_OF; r++) {
        double t0 = now(), c0 = children_cpu();
        if (system(line) != 0)
            return -1.0;
        double t = now() - t0;
        if (best < 0 || t < best) {
            best = t;
            *cpu = children_cpu() - c0;
        }
    }
    return best;
}

static int same_file(const char *a, const char *b)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "cmp -s %s %s", a, b);
    return system(cmd) == 0;
}

static void bench_batch(void)
{
    char cmd[3][512], out[3][64];
    const char *names[3] = {"-j 1", "-j 2", "mpirun -n 2 (-j 1 each)"};
    snprintf(cmd[0], sizeof cmd[0], PD_CLI_PATH " -n %d -j 1 " BATCH_PART, BATCH_DROPS);
    snprintf(cmd[1], sizeof cmd[1], PD_CLI_PATH " -n %d -j 2 " BATCH_PART, BATCH_DROPS);
    snprintf(cmd[2], sizeof cmd[2], PD_MPIRUN " -n 2 --allow-run-as-root --oversubscribe "
             PD_CLI_MPI_PATH " -n %d -j 1 " BATCH_PART, BATCH_DROPS);
    int have_mpi = system("command -v " PD_MPIRUN " >/dev/null") == 0 &&
                   system("test -x " PD_CLI_MPI_PATH) == 0;
    printf("\nbatch speed-up: posedrop %s, %d drops, whole processes, best of %d\n", BATCH_PART,
           BATCH_DROPS, BEST_OF);
    printf("reference: the same command with -j 1\n");
    printf("(cpu/wall: cores the run actually got; below 2, the machine is busy)\n");
    printf("%-26s %10s %9s %9s  %s\n", "run", "wall ms", "cpu/wall", "speed-up", "output");
    double t1 = -1.0;
    for (int k = 0; k < 3; k++) {
        snprintf(out[k], sizeof out[k], "/tmp/posedrop-bench-%d-%d.csv", (int)getpid(), k);
        if (k == 2 && !have_mpi) {
            printf("%-26s %10s %9s %9s  not built (make MPI=1; scripts/install-deps.sh mpi)\n",
                   names[k], "-", "-", "-");
            continue;
        }
        double cpu = 0.0, t = time_command(cmd[k], out[k], &cpu);
        if (k == 0)
            t1 = t;
        if (t < 0 || t1 < 0)
            printf("%-26s %10s %9s %9s  FAILED: %s\n", names[k], "-", "-", "-", cmd[k]);
        else
            printf("%-26s %10.1f %9.2f %8.2fx  %s\n", names[k], 1e3 * t, cpu / t, t1 / t,
                   k == 0 ? "reference" : same_file(out[0], out[k]) ? "identical to -j 1"
                                                                    : "DIFFERENT from -j 1");
    }
    for (int k = 0; k < 3; k++)
        remove(out[k]);
}

/* Arguments pick parts (static, hull, dynamic, engines, batch); none runs them all. */
static int wanted(int argc, char **argv, const char *name)
{
    if (argc < 2)
        return 1;
    for (int i = 1; i < argc; i++)
        if (strcmp(argv[i], name) == 0)
            return 1;
    return 0;
}

int main(int argc, char **argv)
{
    printf("posedrop %s benchmark (best of %d runs each)\n", pd_version(), BEST_OF);
    if (pd_bullet_register() != PD_OK) {
        fprintf(stderr, "bench: the Bullet engine would not register\n");
        return 1;
    }
    if (wanted(argc, argv, "static")) {
        bench_static();
        bench_big_mesh();
        bench_symmetry();
    }
    if (wanted(argc, argv, "hull"))
        bench_hull();
    if (wanted(argc, argv, "dynamic"))
        bench_dynamic();
    if (wanted(argc, argv, "engines"))
        bench_engines();
    if (wanted(argc, argv, "ranges")) {
        dyn_part parts[NDYN];
        issue_parts(parts);
        bench_ranges(parts, NDYN);
        for (int k = 0; k < NDYN; k++)
            dyn_part_free(&parts[k]);
    }
    if (wanted(argc, argv, "batch"))
        bench_batch();
    return 0;
}
