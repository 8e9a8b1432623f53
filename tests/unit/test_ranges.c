/* test_ranges.c: runs whose scene parameters are ranges: a zero-width range
 * is the fixed value, byte for byte, on every engine; the draws do not
 * depend on threads, shards or the engine; the trial records hold them; the
 * tumble; the restitution table's laws against the exact ones. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "check.h"
#include "engine_steps.h"
#include "cli_run.h"
#include "drop_fixture.h"
#include "base/quat.h"
#include "base/vec3.h"
#include "contact/compliant_law.h"
#include "posedrop/bullet.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "sim/sim_model.h"
#include "suites.h"

/* The fixture is the 1 x 2 x 3 cm box (drop_fixture.h): three pose classes
 * that friction, restitution and height move. */
typedef drop_fixture fixture;

static pd_sim_result *sim_run(const fixture *f, const pd_scene *sc, pd_engine_kind engine, long n,
                          int threads, int nshards, int shard)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    o.ndrops = n;
    o.threads = threads;
    o.keep_trials = 1;
    o.nshards = nshards;
    o.shard = shard;
    o.seed = 11;
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    if (pd_sim_run(f->part, f->poses, sc, &o, &r, &d) != PD_OK)
        printf("     pd_sim_run: %s\n", d.message);
    CHECK(r != NULL);
    return r;
}

/* Same counts and the same trial records, byte for byte. */
static int same_result(const pd_sim_result *a, const pd_sim_result *b)
{
    return a && b && a->n == b->n && a->nposes == b->nposes &&
           memcmp(a->count, b->count, sizeof *a->count * (size_t)a->nposes) == 0 &&
           a->collisions == b->collisions &&
           memcmp(a->trials, b->trials, sizeof *a->trials * (size_t)a->n) == 0;
}

/* The drops of a run with scene a and with scene b (impulse 40, a stepping
 * engine 15): the same counts, records and estimates, byte for byte. */
static int same_run(const fixture *f, const pd_scene *a, const pd_scene *b, pd_engine_kind engine)
{
    long n = engine == PD_ENGINE_IMPULSE ? 40 : 15;
    pd_sim_result *x = sim_run(f, a, engine, n, 2, 0, 0);
    pd_sim_result *y = sim_run(f, b, engine, n, 2, 0, 0);
    int same = same_result(x, y) && memcmp(x->p, y->p, sizeof *x->p * (size_t)x->nposes) == 0;
    pd_sim_result_free(x);
    pd_sim_result_free(y);
    return same;
}

static void test_zero_width(const fixture *f)
{
    /* Every parameter given as a range of zero width runs the drops of the
     * fixed values: the same bytes, on each engine; first all at once at
     * the defaults, with the stationary start. */
    pd_scene fixed, zero;
    pd_scene_default(&fixed);
    fixed.initial = PD_INITIAL_STATIONARY;
    /* Degrees to radians as the text does it, for the records to match. */
    CHECK_STATUS(pd_scene_set(&fixed, "vibration", "1.5", NULL), PD_OK);
    zero = fixed;
    const char *const ranges[][2] = {{"height", "0.12:0.12"}, {"belt_speed", "0.05:0.05"},
                                     {"mu", "0.3:0.3"}, {"restitution", "0.3:0.3 log"},
                                     {"vibration", "1.5:1.5"}, {"contact_time", "1x:1x"},
                                     {"tumble", "0:0"}};
    for (int i = 0; i < 7; i++)
        CHECK_STATUS(pd_scene_set(&zero, ranges[i][0], ranges[i][1], NULL), PD_OK);
    /* Nothing varies: no drop draws a value of its own. */
    CHECK(!pd_scene_ranged(&zero) && zero.range[PD_PARAM_MU].kind != PD_DIST_FIXED);
    const pd_engine_kind engines[] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
    const long drops[] = {210, 70, 70};
    for (int e = 0; e < 3; e++) {
        pd_sim_result *a = sim_run(f, &fixed, engines[e], drops[e], 2, 0, 0);
        pd_sim_result *b = sim_run(f, &zero, engines[e], drops[e], 2, 0, 0);
        CHECK(same_result(a, b));
        CHECK(a && b && memcmp(a->p, b->p, sizeof *a->p * (size_t)a->nposes) == 0);
        pd_sim_result_free(a);
        pd_sim_result_free(b);
    }
    /* Then each parameter alone at values away from its default, where
     * whatever the run derives from the scene's own field (the default)
     * rather than the range would show: the resting contact's patch and a
     * top's spin-down follow the restitution and the contact time. */
    static const char *const values[][4] = {
        {"height", "0.05", "0.2", "0.4"},        {"belt_speed", "0", "0.1", "-0.3"},
        {"mu", "0.1", "0.5", "0.9"},             {"restitution", "0.1", "0.45", "0.8"},
        {"vibration", "0", "3", "20"},           {"contact_time", "1e-4", "3e-4", "2e-3"},
        {"tumble", "2", "10", "40"}};
    for (int i = 0; i < 7; i++)
        for (int v = 1; v < 4; v++) {
            pd_scene one;
            pd_scene_default(&one);
            CHECK_STATUS(pd_scene_set(&one, values[i][0], values[i][v], NULL), PD_OK);
            char text[64];
            snprintf(text, sizeof text, "%s:%s", values[i][v], values[i][v]);
            /* The range alone, the field left at the default. */
            pd_scene_default(&zero);
            CHECK_STATUS(pd_scene_set(&zero, values[i][0], text, NULL), PD_OK);
            for (int e = 0; e < 3; e++) {
                int same = same_run(f, &one, &zero, engines[e]);
                if (!same)
                    printf("     %s %s on engine %d: not the fixed run\n", values[i][0], text,
                           e);
                CHECK(same);
            }
        }
}

static void test_deterministic(const fixture *f)
{
    pd_scene sc;
    pd_scene_default(&sc);
    CHECK_STATUS(pd_scene_set(&sc, "mu", "0.1:0.8", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "restitution", "0.1:0.6", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "height", "0.05:0.2", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "contact_time", "0.3x:3x", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "tumble", "0:30", NULL), PD_OK);
    const long n = 120;
    pd_sim_result *one = sim_run(f, &sc, PD_ENGINE_IMPULSE, n, 1, 0, 0);
    pd_sim_result *three = sim_run(f, &sc, PD_ENGINE_IMPULSE, n, 3, 0, 0);
    CHECK(same_result(one, three));
    /* Three shards summed are the whole run; each shard's records are the
     * whole run's drops shard, shard + 3, ... */
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = n;
    o.seed = 11;
    pd_sim_result *sum = NULL;
    CHECK_STATUS(pd_sim_result_new(f->poses, &sc, &o, &sum, NULL), PD_OK);
    int records = 1;
    for (int k = 0; k < 3 && sum && one; k++) {
        pd_sim_result *s = sim_run(f, &sc, PD_ENGINE_IMPULSE, n, 2, 3, k);
        if (!s)
            continue;
        CHECK_STATUS(pd_sim_result_add(sum, s, NULL), PD_OK);
        for (long t = 0; t < s->n; t++)
            records &= memcmp(&s->trials[t], &one->trials[k + 3 * t], sizeof *s->trials) == 0;
        pd_sim_result_free(s);
    }
    CHECK(records);
    CHECK_STATUS(pd_sim_result_finish(sum, NULL), PD_OK);
    CHECK(sum && one && memcmp(sum->count, one->count, sizeof *sum->count * (size_t)sum->nposes) == 0);
    CHECK(sum && one && memcmp(sum->p, one->p, sizeof *sum->p * (size_t)sum->nposes) == 0);
    /* The records hold the drawn values, which are the library's draw of
     * that drop, in the range, whatever the engine. */
    pd_sim_result *ode = sim_run(f, &sc, PD_ENGINE_ODE, 20, 2, 0, 0);
    int drawn = 1, inside = 1, engine_free = 1;
    for (long t = 0; one && t < one->n; t++) {
        double v[PD_NPARAMS];
        pd_scene_draw(&sc, pd_contact_time_auto_size(f->part), 11, t, v, NULL);
        drawn &= memcmp(v, one->trials[t].param, sizeof v) == 0;
        inside &= v[PD_PARAM_MU] >= 0.1 && v[PD_PARAM_MU] <= 0.8 &&
                  v[PD_PARAM_CONTACT_TIME] >= 0.3 * pd_contact_time_auto_part(f->part) * (1 - 1e-15) &&
                  v[PD_PARAM_CONTACT_TIME] <= 3.0 * pd_contact_time_auto_part(f->part) * (1 + 1e-15);
        if (ode && t < ode->n)
            engine_free &= memcmp(v, ode->trials[t].param, sizeof v) == 0 &&
                           memcmp(one->trials[t].q0, ode->trials[t].q0, sizeof v[0] * 4) == 0;
    }
    CHECK(drawn && inside && engine_free);
    /* Ranges move outcomes: the drops are not those of the fixed scene. */
    pd_scene fixed;
    pd_scene_default(&fixed);
    pd_sim_result *plain = sim_run(f, &fixed, PD_ENGINE_IMPULSE, n, 2, 0, 0);
    CHECK(plain && one && !same_result(plain, one));
    pd_sim_result_free(plain);
    pd_sim_result_free(ode);
    pd_sim_result_free(sum);
    pd_sim_result_free(one);
    pd_sim_result_free(three);
}

static void test_tumble(const fixture *f)
{
    /* The release turns at the scene's tumble about an axis uniform over
     * the sphere: |w| exact to round-off, and each component of the axis
     * averaging 0 within 4 standard errors (1 / sqrt(3 n) each). */
    pd_scene sc;
    pd_scene_default(&sc);
    sc.tumble = 40.0;
    pd_sim_options o;
    pd_sim_options_default(&o);
    const pd_sim_model *m = f->model; /* the tumble is no part of the model */
    const int n = 3000;
    pd_vec3 mean = v3(0, 0, 0);
    double worst = 0.0;
    for (int i = 0; i < n; i++) {
        pd_state s;
        pd_trial t;
        pd_drop_release(m, &sc, &o, i, NULL, &s, &t);
        pd_vec3 ww = quat_rotate(s.q, s.w);
        worst = fmax(worst, fabs(v3_norm(ww) - 40.0) / 40.0);
        mean = v3_add(mean, v3_scale(ww, 1.0 / (40.0 * n)));
    }
    CHECK(worst < 1e-14);
    double se = 1.0 / sqrt(3.0 * n);
    CHECK(fabs(mean.x) < 4 * se && fabs(mean.y) < 4 * se && fabs(mean.z) < 4 * se);
    /* Without tumble the release does not turn, and its orientation is the
     * same as with it (the axis comes from the parameters' stream). */
    pd_scene still;
    pd_scene_default(&still);
    pd_state a, b;
    pd_trial ta, tb;
    pd_drop_release(m, &still, &o, 5, NULL, &a, &ta);
    pd_drop_release(m, &sc, &o, 5, NULL, &b, &tb);
    CHECK(v3_norm(a.w) == 0.0 && memcmp(&a.q, &b.q, sizeof a.q) == 0);
    /* Every engine takes it: the drops settle, and not as they do without. */
    const pd_engine_kind engines[] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
    for (int e = 0; e < 3; e++) {
        pd_sim_result *r = sim_run(f, &sc, engines[e], 30, 2, 0, 0);
        pd_sim_result *r0 = sim_run(f, &still, engines[e], 30, 2, 0, 0);
        CHECK(r && r->unsettled == 0);
        int differ = 0;
        for (long t = 0; r && r0 && t < r->n; t++)
            differ += r->trials[t].time != r0->trials[t].time;
        CHECK(differ > 0);
        pd_sim_result_free(r);
        pd_sim_result_free(r0);
    }
}

/* The worst relative error of a table's chi and omega against the exact
 * law's, midway between nodes (where interpolation's error peaks); the
 * table's step there meets the step's tolerance on the exact law, and
 * *step_ratio is lowered to the least ratio of the table's step to the
 * exact law's. */
static double table_error(double e_lo, double e_hi, double *step_ratio)
{
    pd_compliant_table t;
    CHECK_STATUS(pd_compliant_table_init(e_lo, e_hi, &t), PD_OK);
    double worst = 0.0;
    for (int i = 0; i + 1 < t.n; i++) {
        double e = exp(t.x_lo + (i + 0.5) * t.dx);
        pd_compliant_law exact, table;
        CHECK_STATUS(pd_compliant_law_init(e, 1e-3, &exact), PD_OK);
        pd_compliant_table_law(&t, e, 1e-3, &table);
        worst = fmax(worst, fabs(table.chi - exact.chi) / exact.chi);
        worst = fmax(worst, fabs(table.omega - exact.omega) / exact.omega);
        CHECK(pd_compliant_law_step_meets(exact.chi, exact.e, table.step));
        *step_ratio = fmin(*step_ratio, table.step / exact.step);
    }
    return worst;
}

static void test_restitution_table(void)
{
    /* The laws a drawn restitution gets, interpolated between 65 exact ones
     * across the range: within 1e-7 of the exact law for restitutions 0.05
     * to 0.9, 1e-5 for the whole 0.01 to 1 (chi tends to 0 at 1), far below
     * what a restitution is known to (a few percent at best). Its step
     * meets the step's tolerance (PD_COMPLIANT_E_TOL) on the exact law:
     * where there is little damping the error wavers with the step, and
     * an interpolated step alone missed it by up to 2.8 times. */
    double ratio = 1.0;
    CHECK(table_error(0.05, 0.9, &ratio) < 1e-7);
    CHECK(table_error(0.01, 1.0, &ratio) < 1e-5);
    /* Its step, interpolated and shortened where it missed, is not much
     * shorter than the exact law's (measured 0.64 at worst). */
    CHECK(ratio > 0.5);
    if (getenv("PD_TEST_VERBOSE"))
        printf("ranges: a table law's step at least %.3g of the exact law's\n", ratio);
    /* A one-restitution table (a range of zero width): the exact law
     * itself, byte for byte, whatever the restitution and duration. */
    pd_compliant_table t;
    const double es[] = {0.0, 0.11, 0.3, 0.37, 0.93, 1.0}, ts[] = {2e-4, 1e-3, 3.7e-5};
    for (int i = 0; i < 6; i++) {
        CHECK_STATUS(pd_compliant_table_init(es[i], es[i], &t), PD_OK);
        for (int j = 0; j < 3; j++) {
            pd_compliant_law exact, table;
            CHECK_STATUS(pd_compliant_law_init(es[i], ts[j], &exact), PD_OK);
            pd_compliant_table_law(&t, es[i], ts[j], &table);
            CHECK(memcmp(&exact, &table, sizeof exact) == 0);
        }
    }
    CHECK_STATUS(pd_compliant_table_init(0.5, 0.3, &t), PD_ERR_RANGE);
}

#define BOX "parts/canonical/box_1x2x3.off"

/* The command: a zero-width range prints the fixed run's bytes; --trials
 * names the ranged columns; shards of a ranged run merge into it, and not
 * with shards of other ranges; bad ranges are refused before any work; a
 * fragile long run is said on stderr. */
static void test_command(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-ranges-XXXXXX");
    if (!mkdtemp(tmpdir) || access(PD_CLI_PATH, X_OK) != 0) {
        CHECK(!"no scratch directory or no posedrop binary");
        return;
    }
    char *a, *b, *err, *out, cmd[1024], path[160];
    CHECK_INT(run("-n 40 --vibration 1.5 " BOX, &a, &err), 0);
    free(err);
    CHECK_INT(run("-n 40 -h 0.12:0.12 --mu 0.3:0.3 --restitution 0.3:0.3 --vibration 1.5:1.5 "
                  "--contact-time 1x:1x --tumble 0:0 -v 0.05:0.05 " BOX, &b, &err), 0);
    CHECK(a && b && strcmp(a, b) == 0);
    free(a);
    free(b);
    free(err);
    snprintf(path, sizeof path, "%s/t.csv", tmpdir);
    snprintf(cmd, sizeof cmd, "-n 5 --mu 0.2:0.6 --contact-time 0.3x:3x --trials %s " BOX, path);
    CHECK_INT(run(cmd, &out, &err), 0);
    char *t = slurp(path);
    CHECK(t && strncmp(t, "drop,qw,qx,qy,qz,pose,collisions,time,end,mu,contact_time,partial\n", 66) == 0);
    free(t);
    free(out);
    free(err);
    /* A zero-width range is a fixed value: no column. */
    snprintf(cmd, sizeof cmd, "-n 5 --mu 0.4:0.4 --restitution 0.2:0.5 --trials %s " BOX, path);
    CHECK_INT(run(cmd, &out, &err), 0);
    t = slurp(path);
    CHECK(t && strncmp(t, "drop,qw,qx,qy,qz,pose,collisions,time,end,restitution,partial\n", 62) == 0);
    free(t);
    free(out);
    free(err);
    /* Shards. */
    const char *args = "-n 60 --seed 3 --mu 0.1:0.7 --restitution 0.1:0.5 --tumble 0:20 " BOX;
    CHECK_INT(run(args, &a, &err), 0);
    free(err);
    char list[512] = "merge";
    for (int k = 1; k <= 3; k++) {
        snprintf(cmd, sizeof cmd, "(%s %s --shard %d/3 > %s/s%d)", PD_CLI_PATH, args, k, tmpdir,
                 k);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
        free(out);
        free(err);
        snprintf(list + strlen(list), sizeof list - strlen(list), " %s/s%d", tmpdir, k);
    }
    CHECK_INT(run(list, &b, &err), 0);
    CHECK(a && b && strcmp(a, b) == 0);
    free(a);
    free(b);
    free(err);
    snprintf(cmd, sizeof cmd, "(%s -n 60 --seed 3 --mu 0.1:0.8 --restitution 0.1:0.5 --tumble "
             "0:20 %s --shard 3/3 > %s/s3)", PD_CLI_PATH, BOX, tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    expect_failure(list, 2, "mu_range");
    expect_failure("-n 5 --mu 0.5:0.2 " BOX, 2, "low end is above");
    expect_failure("-n 5 --mu 0.2:0.5:normal " BOX, 2, "uniform or log");
    expect_failure("-n 5 --contact-time 0.3x:3 " BOX, 2, "multiples of auto");
    expect_failure("-n 5 -h 1e-320 " BOX, 2, "smallest normal double");
    /* A large part (block.stl read in metres: 46 m across): its auto
     * contact time, 0.21 s (capped where its weight would press a contact
     * 1e-3 of its size into the floor), has no bound, a range's drawn
     * values do: ten times it passes 1 s. */
    CHECK_INT(run("-n 5 parts/block.stl", &out, &err), 0);
    free(out);
    free(err);
    expect_failure("-n 5 --contact-time 0.3x:10x parts/block.stl", 2, "the range reaches");
    snprintf(path, sizeof path, "%s/g.scene", tmpdir);
    write_file(path, "mu = 0.2:0.4\ngravity = 9:10\n");
    char where[200];
    snprintf(cmd, sizeof cmd, "--scene %s -n 5 %s", path, BOX);
    snprintf(where, sizeof where, "%s:2: gravity: takes one value", path);
    expect_failure(cmd, 2, where);
    /* A stationary run whose long run rests on its first drops says so
     * without --verbose: the box's two broad faces each keep every drop
     * started on them (two closed classes), a coin's chain mixes. */
    CHECK_INT(run("-n 700 --initial stationary " BOX, &out, &err), 0);
    CHECK(err && strstr(err, "the long run is fragile") && strstr(err, "2 closed classes") &&
          strstr(err, "{pose 1}, {pose 2}") && strstr(err, "100 uniform first drops"));
    free(out);
    free(err);
    CHECK_INT(run("-n 700 --initial stationary parts/canonical/coin_h0.5.off", &out, &err), 0);
    CHECK(err && !strstr(err, "fragile"));
    free(out);
    free(err);
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0)
        printf("     could not remove %s\n", tmpdir);
}

void suite_ranges(void)
{
    test_command();
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    test_restitution_table();
    fixture f;
    pd_scene sc;
    if (!drop_setup_box(&f, &sc, 0.3))
        return;
    test_zero_width(&f);
    test_deterministic(&f);
    test_tumble(&f);
    drop_teardown(&f);
}
