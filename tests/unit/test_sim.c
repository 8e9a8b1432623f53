/* test_sim.c: the Monte Carlo dynamic estimator: statistics of symmetric
 * parts, determinism whatever the thread count, scale, the run's contracts
 * (cancellation, bootstrap, --ci, trial records), shards summed. */
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "base/gsl_adapter.h"
#include "posedrop/posedrop.h"
#include "posedrop/sim.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

typedef struct {
    pd_part *part;
    pd_static_result *poses;
} part_fixture;

static int make_part(part_fixture *f, pd_mesh *m)
{
    memset(f, 0, sizeof *f);
    int ok = m && pd_part_build(m, NULL, &f->part, NULL) == PD_OK &&
             pd_static_estimate(f->part, NULL, &f->poses, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    return ok;
}

static void free_part(part_fixture *f)
{
    pd_static_result_free(f->poses);
    pd_part_free(f->part);
}

static pd_mesh *scaled(pd_mesh *m, double s)
{
    double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh_transform(m, CR(I), s, v3(0, 0, 0));
    return m;
}

static pd_sim_result *run(const part_fixture *f, const pd_scene *sc, const pd_sim_options *o)
{
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_sim_run(f->part, f->poses, sc, o, &r, &d);
    if (st != PD_OK)
        printf("     pd_sim_run: %s (%s)\n", pd_status_str(st), d.message);
    return r;
}

static void test_platonic_uniform(void)
{
    /* Symmetric solids from uniform orientations end on every face alike:
     * uniform within the 99.9% chi-square bound (a false alarm one run in a
     * thousand; the seed is fixed, so this run's verdict is reproducible). */
    pd_vec3 p[64];
    int (*solids[])(pd_vec3 *) = {pts_tetrahedron, pts_cube, pts_octahedron, pts_icosahedron};
    const long drops[] = {600, 900, 800, 1000};
    for (int s = 0; s < 4; s++) {
        int n = solids[s](p);
        part_fixture f;
        if (!make_part(&f, scaled(convex_mesh(p, n), 0.005)))
            continue;
        pd_sim_options o;
        pd_sim_options_default(&o);
        o.ndrops = drops[s];
        o.seed = 100 + (uint64_t)s;
        pd_sim_result *r = run(&f, NULL, &o);
        CHECK(r != NULL);
        if (r) {
            CHECK_INT(r->n, drops[s]);
            CHECK_INT(r->unsettled, 0);
            CHECK(uniform_p_value(r) > 1e-3);
            double sum = 0;
            for (int k = 0; k < r->nposes; k++)
                sum += r->p[k];
            CHECK_NEAR(sum, 1.0, 1e-12, "all drops settled");
        }
        pd_sim_result_free(r);
        free_part(&f);
    }
}

static void test_determinism_and_scale(void)
{
    /* Same seed, one or two threads: the same counts and the same records,
     * byte for byte. */
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 300;
    o.keep_trials = 1;
    o.threads = 1;
    pd_sim_result *a = run(&f, NULL, &o);
    o.threads = 2;
    pd_sim_result *b = run(&f, NULL, &o);
    CHECK(a && b);
    if (a && b) {
        CHECK(memcmp(a->count, b->count, sizeof *a->count * (size_t)a->nposes) == 0);
        CHECK(memcmp(a->trials, b->trials, sizeof *a->trials * (size_t)a->n) == 0);
        CHECK_INT(a->collisions, b->collisions);
        /* Each record is its own drop: unit quaternions, poses in range. */
        int bad = 0;
        for (long i = 0; i < a->n; i++) {
            const double *q = a->trials[i].q0;
            bad += fabs(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] - 1) > 1e-12;
            bad += a->trials[i].pose < -1 || a->trials[i].pose >= a->nposes;
        }
        CHECK_INT(bad, 0);
    }
    pd_sim_result_free(a);
    pd_sim_result_free(b);
    free_part(&f);

    /* Parts of 1 mm and 1 m: drops end and the cube stays uniform. */
    const double sizes[] = {1e-3, 1.0};
    for (int i = 0; i < 2; i++) {
        pd_vec3 p[8];
        part_fixture c;
        if (!make_part(&c, scaled(convex_mesh(p, pts_cube(p)), sizes[i] / 2)))
            continue;
        pd_sim_options_default(&o);
        o.ndrops = 600;
        pd_sim_result *r = run(&c, NULL, &o);
        CHECK(r != NULL);
        if (r) {
            CHECK_INT(r->unsettled, 0);
            CHECK(uniform_p_value(r) > 1e-3);
        }
        pd_sim_result_free(r);
        free_part(&c);
    }
}

static void test_contracts(void)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    pd_sim_options o;
    pd_scene sc;

    /* Cancelled before it starts: nothing run, marked partial, still valid. */
    pd_sim_options_default(&o);
    atomic_int stop = 1;
    o.cancel = &stop;
    pd_sim_result *r = run(&f, NULL, &o);
    CHECK(r != NULL && r->partial == 1 && r->n == 0);
    pd_sim_result_free(r);

    /* The paper's bootstrap: runs in rounds and reports how stationary the
     * last round was. */
    pd_sim_options_default(&o);
    o.ndrops = 420;
    pd_scene_default(&sc);
    sc.initial = PD_INITIAL_BOOTSTRAP;
    r = run(&f, &sc, &o);
    CHECK(r != NULL);
    if (r) {
        CHECK_INT(r->n, 420);
        CHECK_INT(r->bootstrap_rounds, 4); /* 20 uniform, then 4 rounds of 100 */
        CHECK(r->stationarity >= 0.0 && r->stationarity <= 1.0);
    }
    pd_sim_result_free(r);

    /* --ci: drops the corrected eq. (17) bound, then more until every 95%
     * interval is within 0.04. */
    pd_sim_options_default(&o);
    o.ndrops = 1;
    o.ci_halfwidth = 0.04;
    r = run(&f, NULL, &o);
    CHECK(r != NULL);
    if (r) {
        int within = 1;
        for (int k = 0; k < r->nposes; k++)
            within &= r->p[k] - r->ci_lo[k] <= 0.04 && r->ci_hi[k] - r->p[k] <= 0.04;
        CHECK(within);
        /* At least the worst-case bound for 6 poses at once, 1088 drops. */
        CHECK(r->n >= 1088);
    }
    pd_sim_result_free(r);

    /* Bad options are refused with a message. */
    pd_sim_options_default(&o);
    o.time_limit = 0;
    pd_diag d;
    pd_diag_init(&d);
    r = NULL;
    CHECK_STATUS(pd_sim_run(f.part, f.poses, NULL, &o, &r, &d), PD_ERR_USAGE);
    CHECK(r == NULL && d.message[0] != '\0');
    free_part(&f);
}

/* The library's shards: N runs with nshards = N summed by
 * pd_sim_result_add and finished give the whole run's result, every count
 * and every double equal (the drops keep their indices; sums of integers),
 * for a uniform and a stationary start; each shard runs pd_shard_drops of
 * the drops, which add up to the run's. A shard that does not fit is
 * refused. */
static void test_shards(void)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    for (int stationary = 0; stationary < 2; stationary++) {
        pd_scene sc;
        pd_scene_default(&sc);
        sc.initial = stationary ? PD_INITIAL_STATIONARY : PD_INITIAL_UNIFORM;
        pd_sim_options o;
        pd_sim_options_default(&o);
        o.ndrops = 143; /* not a multiple of any N below */
        o.seed = 11;
        o.threads = 2;
        pd_sim_result *whole = run(&f, &sc, &o), *sum = NULL;
        CHECK(whole != NULL);
        for (int n = 1; whole && n <= 5; n += 2) {
            CHECK_STATUS(pd_sim_result_new(f.poses, &sc, &o, &sum, NULL), PD_OK);
            long drops = 0;
            for (int k = 0; sum && k < n; k++) {
                pd_sim_options os = o;
                os.nshards = n;
                os.shard = k;
                pd_sim_result *part = run(&f, &sc, &os);
                CHECK(part != NULL);
                if (!part)
                    break;
                CHECK_INT(part->n, pd_shard_drops(o.ndrops, k, n));
                drops += part->n;
                CHECK_STATUS(pd_sim_result_add(sum, part, NULL), PD_OK);
                pd_sim_result_free(part);
            }
            CHECK_INT(drops, o.ndrops);
            CHECK_STATUS(pd_sim_result_finish(sum, NULL), PD_OK);
            size_t k = (size_t)whole->nposes;
            CHECK(sum->n == whole->n && sum->unsettled == whole->unsettled &&
                  sum->collisions == whole->collisions);
            CHECK(memcmp(sum->count, whole->count, k * sizeof *sum->count) == 0);
            CHECK(memcmp(sum->p, whole->p, k * sizeof *sum->p) == 0);
            CHECK(memcmp(sum->ci_lo, whole->ci_lo, k * sizeof *sum->ci_lo) == 0);
            CHECK(memcmp(sum->ci_hi, whole->ci_hi, k * sizeof *sum->ci_hi) == 0);
            if (stationary)
                CHECK(sum->closed_classes == whole->closed_classes &&
                      memcmp(sum->transitions, whole->transitions,
                             k * k * sizeof *sum->transitions) == 0);
            pd_sim_result_free(sum);
            sum = NULL;
        }
        /* Another seed's shard does not fit. */
        CHECK_STATUS(pd_sim_result_new(f.poses, &sc, &o, &sum, NULL), PD_OK);
        pd_sim_options other = o;
        other.seed = 12;
        other.nshards = 2;
        pd_sim_result *wrong = run(&f, &sc, &other);
        if (sum && wrong)
            CHECK_STATUS(pd_sim_result_add(sum, wrong, NULL), PD_ERR_USAGE);
        pd_sim_result_free(wrong);
        pd_sim_result_free(sum);
        pd_sim_result_free(whole);
    }
    /* Drop i belongs to shard i mod N. */
    CHECK_INT(pd_shard_of(10, 3), 1);
    CHECK_INT(pd_shard_drops(10, 0, 3), 4);
    CHECK_INT(pd_shard_drops(10, 2, 3), 3);
    CHECK_INT(pd_shard_drops(2, 2, 3), 0);
    free_part(&f);
}

void suite_sim(void)
{
    test_shards();
    test_platonic_uniform();
    test_determinism_and_scale();
    test_contracts();
}
