/* test_sim.c: the Monte Carlo dynamic estimator: statistics of symmetric
 * parts, determinism whatever the thread count, scale, the run's contracts
 * (cancellation, bootstrap, --ci, trial records), shards summed; drops
 * cancelled in flight, the time limit, and why a drop did not settle. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "engine_steps.h"
#include "contact/compliant.h"
#include "sim/drop.h"
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
    o.time_limit = -1;
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

/* --- cancelling drops in flight ---------------------------------------------- */

/* The model of part f on an engine, for scene sc, and a work area, to run
 * drops one by one through the loop pd_sim_run's threads call. */
typedef struct {
    pd_sim_model *m;
    pd_drop_work *w;
} drop_model;

/* 0 (a check counted) on failure, with d freed. */
static int drop_model_build(drop_model *d, const part_fixture *f, const pd_scene *sc,
                            pd_engine_kind engine)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    d->m = NULL;
    CHECK_STATUS(pd_sim_model_build(f->part, f->poses, sc, &o, &d->m, NULL), PD_OK);
    d->w = d->m ? pd_drop_work_alloc(d->m, sc) : NULL;
    CHECK(d->w != NULL);
    if (!d->w)
        pd_sim_model_free(d->m);
    return d->w != NULL;
}

static void drop_model_free(drop_model *d)
{
    pd_drop_work_free(d->w);
    pd_sim_model_free(d->m);
}

/* Drop i of the default options on that engine, with that cancel flag. */
static pd_trial drop_one(const drop_model *d, const pd_scene *sc, pd_engine_kind engine, long i,
                         pd_cancel_flag *cancel)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    o.cancel = cancel;
    pd_trial t;
    long gain = 0, fallbacks = 0;
    pd_drop_run(d->m, d->w, sc, &o, i, NULL, &t, &gain, &fallbacks);
    return t;
}

static void stop_on_progress(void *user, long done, long total)
{
    (void)done;
    (void)total;
    atomic_store((pd_cancel_flag *)user, 1);
}

/* Cancelled from the progress callback after the calling thread's first
 * drop, while the other thread's is in flight (or about to start): the run
 * is partial and its n drops are the first n of the full run, record for
 * record, so a drop stopped part way was not counted and no later drop was
 * either. */
static void test_cancel_in_flight(pd_engine_kind engine)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    o.ndrops = 200;
    o.keep_trials = 1;
    o.threads = 1;
    pd_sim_result *full = run(&f, NULL, &o);
    pd_cancel_flag stop = 0;
    o.threads = 2;
    o.cancel = &stop;
    o.progress = stop_on_progress;
    o.progress_user = &stop;
    pd_sim_result *r = run(&f, NULL, &o);
    CHECK(full != NULL && r != NULL);
    if (full && r) {
        CHECK_INT(r->partial, 1);
        CHECK(r->n < o.ndrops);
        CHECK(r->n == 0 || memcmp(r->trials, full->trials, sizeof *r->trials * (size_t)r->n) == 0);
        long counted = r->unsettled, collisions = 0;
        for (int k = 0; k < r->nposes; k++)
            counted += r->count[k];
        for (long i = 0; i < r->n; i++)
            collisions += full->trials[i].collisions;
        CHECK_INT(counted, r->n);
        CHECK_INT(r->collisions, collisions);
    }
    pd_sim_result_free(full);
    pd_sim_result_free(r);
    free_part(&f);
}

/* A drop whose cancel flag is already set returns at once on any engine and
 * any part: not run (left out of a partial result), no simulated time, no
 * collision; here on parts whose drops are long (a 0.1 mm cube spins for
 * seconds on the impulse engine; a 1000 m cube takes ODE and Bullet up to a
 * million steps). The same drop without the flag runs. */
static void test_cancel_before_drop(void)
{
    const pd_engine_kind engines[] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    for (int e = 0; e < 3; e++) {
        part_fixture f;
        double edge = engines[e] == PD_ENGINE_IMPULSE ? 1e-4 : 1e3;
        if (!make_part(&f, mesh_box(edge, edge, edge)))
            continue;
        pd_scene sc;
        pd_scene_default(&sc);
        drop_model d;
        pd_cancel_flag stop = 1;
        for (long i = 0; i < 3 && drop_model_build(&d, &f, &sc, engines[e]); i++) {
            pd_trial t = drop_one(&d, &sc, engines[e], i, &stop);
            CHECK(t.end == PD_END_NOT_RUN);
            CHECK(t.time == 0.0 && t.collisions == 0);
            drop_model_free(&d);
        }
        free_part(&f);
    }
}

/* The compliant impact, the one call of the impulse engine's drop that can
 * run for most of a drop's simulated time, stops at its first step once the
 * flag it watches is set, and runs without it: a cube landing on a corner
 * at the speed of a 0.12 m fall. */
static void test_cancel_compliant(void)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.01, 0.01)))
        return;
    pd_scene sc;
    pd_scene_default(&sc);
    drop_model d;
    if (!drop_model_build(&d, &f, &sc, PD_ENGINE_IMPULSE)) {
        free_part(&f);
        return;
    }
    const pd_sim_model *m = d.m;
    CHECK(m->compliant_on);
    for (int set = 0; m->compliant_on && set < 2; set++) {
        pd_state s = {v3(0, 0, 0), quat_normalize(quat(0.9, 0.3, 0.2, 0.1)), v3(0.05, 0, -1.5),
                      v3(0, 0, 0)};
        double low = HUGE_VAL;
        for (int i = 0; i < m->body->nverts; i++)
            low = fmin(low, pd_body_vertex_world(m->body, &s, i).z);
        s.x.z = -low;
        pd_cancel_flag stop = set;
        pd_compliant_work_watch(d.w->compliant_work, &stop);
        pd_compliant_result cr;
        CHECK_STATUS(pd_compliant_run(&m->compliant, d.w->compliant_work, &m->settle, &sc, &s,
                                      1.0, &cr), PD_OK);
        CHECK(set ? cr.end == PD_COMPLIANT_CANCELLED && cr.steps == 0 && cr.time == 0.0
                  : cr.end != PD_COMPLIANT_CANCELLED && cr.steps > 0);
    }
    drop_model_free(&d);
    free_part(&f);
}

/* --- the time limit and why drops end ------------------------------------- */

/* Every stage has its own name, which the command prints in --trials. */
static void test_stage_names(void)
{
    for (int a = 0; a < PD_STAGE_COUNT; a++) {
        CHECK(strcmp(pd_drop_stage_name((pd_drop_stage)a), "unknown") != 0);
        for (int b = 0; b < a; b++)
            CHECK(strcmp(pd_drop_stage_name((pd_drop_stage)a),
                         pd_drop_stage_name((pd_drop_stage)b)) != 0);
    }
    CHECK(strcmp(pd_drop_stage_name(PD_STAGE_COUNT), "unknown") == 0);
}

/* A drop that cannot go on says where and how: released from a height that
 * is not a number (pd_sim_run refuses it; the drop loop is called directly),
 * the impulse engine's flight and the stepping engines' reset meet a
 * non-finite state. */
static void test_failure_reason(void)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    const pd_engine_kind engines[] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
    const pd_drop_stage stages[] = {PD_STAGE_FLIGHT, PD_STAGE_ENGINE_RESET,
                                    PD_STAGE_ENGINE_RESET};
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    for (int e = 0; e < 3; e++) {
        pd_scene sc;
        pd_scene_default(&sc);
        drop_model d;
        if (!drop_model_build(&d, &f, &sc, engines[e]))
            continue;
        sc.height = NAN;
        pd_trial t = drop_one(&d, &sc, engines[e], 0, NULL);
        CHECK(t.end == PD_END_FAILED && t.pose < 0);
        CHECK_INT(t.stage, stages[e]);
        CHECK_STATUS(t.status, PD_ERR_NONFINITE);
        drop_model_free(&d);
    }
    free_part(&f);
}

/* The run's counts say how its drops ended: with a limit too short for any
 * drop to settle, every drop ends at it, none failed. */
static void test_end_counts(void)
{
    part_fixture f;
    if (!make_part(&f, mesh_box(0.01, 0.02, 0.03)))
        return;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 20;
    o.keep_trials = 1;
    o.time_limit = 0.05; /* the fall from 0.12 m takes 0.156 s */
    pd_sim_result *r = run(&f, NULL, &o);
    CHECK(r != NULL);
    if (r) {
        CHECK_INT(r->unsettled, 20);
        CHECK_INT(r->time_limited, 20);
        CHECK_INT(r->collision_limited + r->failed, 0);
        CHECK_INT(r->first_failed, -1);
        CHECK(r->time_limit == 0.05);
        for (long i = 0; i < r->n; i++)
            CHECK(r->trials[i].end == PD_END_TIME_LIMIT && r->trials[i].stage == PD_STAGE_NONE &&
                  r->trials[i].status == PD_OK);
    }
    pd_sim_result_free(r);
    free_part(&f);
}

/* The automatic time limit is the one the drops run with, for the part and
 * scene at hand: elastic frictionless rigid drops never settle, and each
 * that ends at the limit ends within a step of it (a step is far below 1e-3
 * of the limit: rest steps take a rest fall, phases end at the limit), for a
 * 1 cm box and a 10 m one, whose limits differ by the closed form's ratio. */
static void test_time_limit_auto(void)
{
    const double sizes[] = {0.01, 10.0};
    CHECK_NEAR(pd_time_limit_auto(0.01 * sqrt(3.0), NULL), 19.84, 0.005,
               "the figure sim.h and docs/cli.md quote, rounded");
    for (int k = 0; k < 2; k++) {
        part_fixture f;
        if (!make_part(&f, scaled(mesh_box(1, 2, 3), sizes[k])))
            continue;
        pd_scene sc;
        pd_scene_default(&sc);
        sc.mu = 0.0;
        sc.restitution = 1.0;
        sc.contact_time = 0.0;
        double limit = pd_time_limit_auto(f.part->size, &sc);
        CHECK_REL(limit, PD_TIME_LIMIT_UNITS * (sqrt(f.part->size / sc.gravity) +
                                                sqrt(2.0 * sc.height / sc.gravity)),
                  1e-15, "closed form, round-off");
        pd_sim_options o;
        pd_sim_options_default(&o);
        o.ndrops = 3;
        o.keep_trials = 1;
        pd_sim_result *r = run(&f, &sc, &o);
        CHECK(r != NULL);
        if (r) {
            CHECK(r->time_limit == limit);
            CHECK(r->time_limited > 0);
            for (long i = 0; i < r->n; i++)
                if (r->trials[i].end == PD_END_TIME_LIMIT)
                    CHECK(r->trials[i].time >= limit && r->trials[i].time < limit * (1 + 1e-3));
        }
        pd_sim_result_free(r);
        free_part(&f);
    }
}

void suite_sim(void)
{
    test_shards();
    test_platonic_uniform();
    test_determinism_and_scale();
    test_contracts();
    test_cancel_in_flight(PD_ENGINE_IMPULSE);
    test_cancel_in_flight(PD_ENGINE_ODE);
    test_cancel_before_drop();
    test_cancel_compliant();
    test_stage_names();
    test_failure_reason();
    test_end_counts();
    test_time_limit_auto();
}
