/* test_sensitivity.c: the first-order index on cases whose answer is known
 * by construction: on given (x, y) data, on a run's records made to order,
 * and on drops whose outcome cannot depend on the parameter. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/rng.h"
#include "check.h"
#include "cli_run.h"
#include "xmlcheck.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"

/* n pairs: x uniform on [0, 1), and y = f(x, z) with z an independent
 * uniform. */
static void pairs(uint64_t seed, long n, int kind, double *x, double *y)
{
    pd_rng r;
    pd_rng_init(&r, seed, 0);
    for (long j = 0; j < n; j++) {
        double u = pd_rng_uniform(&r), z = pd_rng_uniform(&r);
        x[j] = u;
        switch (kind) {
        case 0: y[j] = z < 0.3; break;            /* independent of x: S = 0 */
        case 1: y[j] = u > 0.4; break;            /* decided by x: S = 1 */
        case 2: y[j] = u + z > 1.0; break;        /* E[Y|x] = x: S = (1/12) / (1/4) = 1/3 */
        default: y[j] = 3.0 * u + z; break;       /* real y: S = 9 / (9 + 1) = 0.9 */
        }
    }
}

static void test_given_data(void)
{
    enum { N = 4000 };
    double *x = malloc(sizeof *x * N), *y = malloc(sizeof *y * N);
    if (!x || !y) {
        CHECK(!"out of memory");
        free(x);
        free(y);
        return;
    }
    double s, lo, hi;
    /* Independent: the interval holds 0; the estimate within a few of its
     * standard errors, sqrt(2 (M - 1)) / n = 0.0023 for M = 64 bins. */
    pairs(1, N, 0, x, y);
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s, &lo, &hi, NULL), PD_OK);
    CHECK(lo == 0.0 && hi >= s && s < 0.01 && hi < 0.03);
    /* Decided by x alone: near 1; only the bin holding the threshold mixes
     * (1 of 64), so S is at least 1 - 2 / 64. */
    pairs(2, N, 1, x, y);
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s, &lo, &hi, NULL), PD_OK);
    CHECK(s > 1.0 - 2.0 / 64 && lo > 0.95 && hi <= 1.0);
    /* A real y, 3 x + z: 0.9 within the interval, the interval narrow. */
    pairs(3, N, 3, x, y);
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s, &lo, &hi, NULL), PD_OK);
    CHECK(lo <= 0.9 && 0.9 <= hi && hi - lo < 0.02);
    /* The same data and seed, the same bytes; a y that does not vary: 0. */
    double s2, lo2, hi2;
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s2, &lo2, &hi2, NULL), PD_OK);
    CHECK(s2 == s && lo2 == lo && hi2 == hi);
    for (long j = 0; j < N; j++)
        y[j] = 1.0;
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s, &lo, &hi, NULL), PD_OK);
    CHECK(s == 0.0 && lo == 0.0 && hi == 0.0);
    /* Refusals. */
    CHECK_STATUS(pd_first_order_index(x, y, 3, 5, &s, &lo, &hi, NULL), PD_ERR_USAGE);
    CHECK_STATUS(pd_first_order_index(NULL, y, N, 5, &s, &lo, &hi, NULL), PD_ERR_USAGE);
    x[7] = NAN;
    CHECK_STATUS(pd_first_order_index(x, y, N, 5, &s, &lo, &hi, NULL), PD_ERR_NONFINITE);

    /* Coverage: y = [x + z > 1] has S = 1/3. Over 100 data sets of 1000
     * pairs the 95% interval should hold it about 95 times; fewer than 85
     * has probability below 1e-4 if the coverage is 95% (binomial), so a
     * failure means the interval is too narrow or off centre. */
    int held = 0;
    for (int rep = 0; rep < 100; rep++) {
        pairs(100 + (uint64_t)rep, 1000, 2, x, y);
        CHECK_STATUS(pd_first_order_index(x, y, 1000, (uint64_t)rep, &s, &lo, &hi, NULL), PD_OK);
        held += lo <= 1.0 / 3.0 && 1.0 / 3.0 <= hi;
    }
    if (held < 85)
        printf("     coverage %d of 100\n", held);
    CHECK(held >= 85);
    free(x);
    free(y);
}

/* A run's records made to order: the pose is 1 when the drawn friction is
 * above 0.5, else 2; the restitution is ranged but moves nothing. */
/* A pose table of two poses for results made by hand (pd_sim_result_new
 * reads its pose count and identity). */
static pd_pose two_pose_table[2];
static const pd_static_result two_poses = {.nposes = 2, .poses = two_pose_table};

/* A two-pose run of n settled drops made by hand, its scene sc with mu
 * 0.2:0.8, restitution `e` and contact time 0.3x:3x ranged: each record
 * holds its drop's drawn values; the caller sets the poses. NULL on
 * failure. */
static pd_sim_result *made_run(pd_scene *sc, const char *e, long n)
{
    pd_scene_default(sc);
    CHECK_STATUS(pd_scene_set(sc, "mu", "0.2:0.8", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(sc, "restitution", e, NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(sc, "contact_time", "0.3x:3x", NULL), PD_OK);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = n;
    pd_sim_result *r = NULL;
    CHECK_STATUS(pd_sim_result_new(&two_poses, sc, &o, &r, NULL), PD_OK);
    if (!r)
        return NULL;
    r->trials = calloc((size_t)n, sizeof *r->trials);
    r->n = r->trials ? n : 0;
    for (long t = 0; t < r->n; t++) {
        pd_scene_draw(sc, 0.01, o.seed, t, r->trials[t].param, NULL);
        r->trials[t].end = PD_END_SETTLED;
    }
    return r;
}

static void test_records(void)
{
    pd_scene sc;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 3000;
    pd_sim_result *r = made_run(&sc, "0.1:0.5", o.ndrops);
    if (!r)
        return;
    for (long t = 0; t < r->n; t++) {
        pd_trial *tr = &r->trials[t];
        tr->pose = tr->param[PD_PARAM_MU] > 0.5 ? 0 : 1;
    }
    pd_sensitivity *s = NULL;
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, NULL, 0, &s, NULL), PD_OK);
    CHECK(s && s->n == 3000 && s->nposes == 2 && s->nparams == 3);
    if (s && s->nparams == 3) {
        CHECK(s->param[0] == PD_PARAM_MU && s->param[1] == PD_PARAM_RESTITUTION &&
              s->param[2] == PD_PARAM_CONTACT_TIME);
        for (int pose = 0; pose < 2; pose++) {
            const pd_sensitivity_row *mu = &s->rows[pose * 3 + 0];
            const pd_sensitivity_row *e = &s->rows[pose * 3 + 1];
            CHECK(mu->pose == pose && mu->index > 0.95 && mu->index_lo > 0.9);
            CHECK(e->index_lo == 0.0 && e->index < 0.02);
            /* The thirds: friction below 0.4 never ends in pose 1, above
             * 0.6 always; each third about 1000 drops. */
            CHECK(mu->p_low == (pose == 0 ? 0.0 : 1.0) && mu->p_high == (pose == 0 ? 1.0 : 0.0));
            CHECK(labs(mu->n_low - 1000) < 100 && labs(mu->n_high - 1000) < 100);
            CHECK(mu->p_low_lo <= mu->p_low && mu->p_low <= mu->p_low_hi);
        }
    }
    pd_sensitivity_free(s);
    /* Classes: both poses in one class, which never varies. */
    int one[2] = {0, 0};
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, one, 1, &s, NULL), PD_OK);
    CHECK(s && s->nposes == 1 && s->rows[0].index == 0.0 && s->rows[0].index_hi == 0.0);
    pd_sensitivity_free(s);
    int bad[2] = {0, 3};
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, bad, 2, &s, NULL), PD_ERR_USAGE);
    free(r->trials);
    r->trials = NULL;
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, NULL, 0, &s, NULL), PD_ERR_USAGE);
    pd_sim_result_free(r);

    /* A stationary run's records: only the drops started uniform count,
     * 1000 of 3000 with two poses (drops 0, 3, 6, ...). */
    sc.initial = PD_INITIAL_STATIONARY;
    CHECK_STATUS(pd_sim_result_new(&two_poses, &sc, &o, &r, NULL), PD_OK);
    if (!r)
        return;
    r->trials = calloc((size_t)o.ndrops, sizeof *r->trials);
    r->n = r->trials ? o.ndrops : 0;
    for (long t = 0; t < r->n; t++) {
        pd_scene_draw(&sc, 0.01, o.seed, t, r->trials[t].param, NULL);
        r->trials[t].end = PD_END_SETTLED;
        r->trials[t].pose = t % 3 == 0 ? r->trials[t].param[PD_PARAM_MU] > 0.5 : 0;
    }
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, NULL, 0, &s, NULL), PD_OK);
    CHECK(s && s->n == 1000 && r->pose_drops == 1000 && s->rows[0].index > 0.95);
    pd_sensitivity_free(s);
    free(r->trials);
    r->trials = NULL;
    pd_sim_result_free(r);
}

/* Effects and an interaction made to order: a drop ends in pose 1 with
 * probability 0.3, or 0.7 when both the friction and the restitution fall
 * in the upper thirds of their ranges. Each of the two then moves pose 1
 * by 0.4 / 3 across its range (0.3 in the lower third, 0.3 + 0.4 / 3 in
 * the upper), all of it in the other's upper third (effects 0, 0, 0.4 by
 * the other's thirds); the contact time moves nothing. 6000 drops: about
 * 2000 in a third, an effect's standard error about 0.015, a cell's
 * (a ninth of the drops) about 0.037. */
static void test_effects(void)
{
    pd_scene sc;
    pd_sim_result *r = made_run(&sc, "0.1:0.7", 6000);
    if (!r)
        return;
    pd_rng rng;
    pd_rng_init(&rng, 5, 0);
    for (long t = 0; t < r->n; t++) {
        pd_trial *tr = &r->trials[t];
        int both = tr->param[PD_PARAM_MU] > 0.6 && tr->param[PD_PARAM_RESTITUTION] > 0.5;
        tr->pose = pd_rng_uniform(&rng) < (both ? 0.7 : 0.3) ? 0 : 1;
    }
    pd_sensitivity *s = NULL;
    CHECK_STATUS(pd_sim_sensitivity(r, &sc, 0.01, NULL, 0, &s, NULL), PD_OK);
    CHECK(s && s->nparams == 3 && s->interaction_tests == 2 * 3 * 2);
    double widest = 0.0;
    for (int k = 0; s && s->nparams == 3 && k < 2 * 3; k++) {
        const pd_sensitivity_row *row = &s->rows[k];
        int pose = k / 3, col = k % 3;
        double sign = pose == 0 ? 1.0 : -1.0, truth = col < 2 ? sign * 0.4 / 3.0 : 0.0;
        /* Within 4 standard errors of the truth (0.06). */
        CHECK_NEAR(row->effect, truth, 0.06, "4 standard errors");
        CHECK(row->effect == row->p_high - row->p_low);
        /* The bootstrap's half-width against the binomial one, 1.96 times
         * sqrt(p (1 - p) / n) of the two thirds summed: 200 resamples put
         * its ends within some 10% (tolerance 20%). */
        double se = sqrt(row->p_low * (1 - row->p_low) / (double)row->n_low +
                         row->p_high * (1 - row->p_high) / (double)row->n_high);
        CHECK_NEAR(0.5 * (row->effect_hi - row->effect_lo), 1.96 * se, 0.2 * 1.96 * se,
                   "200 resamples' percentiles");
        widest = fmax(widest, 0.5 * (row->effect_hi - row->effect_lo));
        if (col < 2) {
            /* 9 standard errors clear of 0: flagged, with the other as the
             * partner, the change of about 0.4 within 4 of a cell's
             * standard errors (0.05 each, two cells: 0.21). */
            CHECK(sign * row->effect_lo > 0.0);
            CHECK_INT(row->interacts, col == 0 ? PD_PARAM_RESTITUTION : PD_PARAM_MU);
            CHECK_NEAR(row->effect_in[2] - row->effect_in[0], sign * 0.4, 0.21, "4 standard errors");
            CHECK_NEAR(row->effect_in[0], 0.0, 0.15, "4 standard errors");
            CHECK(row->interaction_lo <= row->interaction &&
                  row->interaction <= row->interaction_hi);
        }
    }
    CHECK(s && s->resolution == widest);
    pd_sensitivity_free(s);
    free(r->trials);
    r->trials = NULL;
    pd_sim_result_free(r);
}

/* Real drops: without friction nothing acts along the floor, so the belt's
 * speed only carries the part sideways and cannot change where it rests;
 * its index's interval must hold 0 (an icosahedron, nearly a sphere). The
 * restitution, which does change the bounces, is ranged beside it. */
static void test_frictionless_belt(void)
{
    pd_vec3 p[16];
    int n = pts_icosahedron(p);
    for (int i = 0; i < n; i++)
        p[i] = (pd_vec3){0.005 * p[i].x, 0.005 * p[i].y, 0.005 * p[i].z};
    pd_mesh *m = convex_mesh(p, n);
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    int ok = m && pd_part_build(m, NULL, &part, NULL) == PD_OK &&
             pd_static_estimate(part, NULL, &poses, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    pd_scene sc;
    pd_scene_default(&sc);
    CHECK_STATUS(pd_scene_set(&sc, "mu", "0", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "belt_speed", "0:1", NULL), PD_OK);
    CHECK_STATUS(pd_scene_set(&sc, "restitution", "0.1:0.6", NULL), PD_OK);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 800;
    o.keep_trials = 1;
    o.seed = 3;
    pd_sim_result *r = NULL;
    pd_sensitivity *s = NULL;
    if (ok && pd_sim_run(part, poses, &sc, &o, &r, NULL) == PD_OK)
        CHECK_STATUS(pd_sim_sensitivity(r, &sc, pd_contact_time_auto_size(part), NULL, 0, &s, NULL),
                     PD_OK);
    CHECK(s != NULL);
    for (int k = 0; s && k < s->nposes; k++) {
        const pd_sensitivity_row *belt = &s->rows[k * s->nparams];
        CHECK(belt->param == PD_PARAM_BELT_SPEED && belt->index_lo == 0.0);
    }
    pd_sensitivity_free(s);
    pd_sim_result_free(r);
    pd_static_result_free(poses);
    pd_part_free(part);
}

/* The command: --sensitivity's CSV names its columns and has a row per
 * class and ranged parameter; the report shows it in words and as a chart,
 * well formed; refusals. */
static void test_command(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-sens-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        CHECK(!"no scratch directory");
        return;
    }
    char cmd[1024], csv[160], html[160], *out, *err;
    snprintf(csv, sizeof csv, "%s/s.csv", tmpdir);
    snprintf(html, sizeof html, "%s/r.html", tmpdir);
    snprintf(cmd, sizeof cmd, "-n 300 -j 2 --group --mu 0.05:0.8 -h 0.01:0.2 --sensitivity %s "
             "--report %s parts/canonical/coin_h0.5.off", csv, html);
    CHECK_INT(run(cmd, &out, &err), 0);
    char *c = slurp(csv), *r = slurp(html);
    const char *head = "pose,parameter,effect,effect_lo,effect_hi,n_low,p_low,p_low_lo,p_low_hi,"
                       "n_high,p_high,p_high_lo,p_high_hi,index,index_lo,index_hi,interacts,"
                       "effect_in_low,effect_in_middle,effect_in_high,interaction,interaction_lo,"
                       "interaction_hi,partial\n";
    CHECK(c && strncmp(c, head, strlen(head)) == 0);
    int rows = 0;
    for (char *p = c; p && *p; p++)
        rows += *p == '\n';
    CHECK_INT(rows, 1 + 2 * 2); /* two classes (heads, tails), two ranges */
    CHECK(c && strstr(c, "\n1,mu,") && strstr(c, "\n2,height,") && !strstr(c, "nan"));
    char msg[256];
    int ok = r && xml_check(r, NULL, msg, sizeof msg);
    if (!ok)
        printf("     report: %s\n", msg);
    CHECK(ok);
    CHECK(r && strstr(r, "What each ranged parameter moves") && strstr(r, "Pose 1: ") &&
          strstr(r, "friction") && strstr(r, "initial uniform"));
    free(c);
    free(r);
    free(out);
    free(err);
    /* --effect: drops until every effect's interval is within 0.08 on
     * each side (from 200 drops, about 600 needed), the same bytes on one
     * thread and two. */
    char *once = NULL;
    for (int threads = 1; threads <= 2; threads++) {
        snprintf(cmd, sizeof cmd, "-n 200 -j %d --group --effect 0.08 --mu 0.05:0.8 "
                 "--sensitivity %s parts/canonical/coin_h0.5.off", threads, csv);
        CHECK_INT(run(cmd, &out, &err), 0);
        c = slurp(csv);
        int rows_ok = c != NULL, nrows = 0;
        for (char *line = c ? strchr(c, '\n') : NULL; line && line[1];
             line = strchr(line + 1, '\n')) {
            double e, lo, hi;
            rows_ok = rows_ok && sscanf(line + 1, "%*d,%*[^,],%lf,%lf,%lf", &e, &lo, &hi) == 3 &&
                      lo <= e && e <= hi && hi - lo <= 2 * 0.08;
            nrows++;
        }
        CHECK(rows_ok && nrows == 2);
        CHECK(err && strstr(err, "resolve an effect to"));
        if (threads == 1)
            once = c;
        else {
            CHECK(once && c && strcmp(once, c) == 0);
            free(c);
        }
        free(out);
        free(err);
    }
    free(once);
    expect_failure("-n 20 --effect 0.05 parts/cap.off", 2, "--effect needs a scene with a range");
    expect_failure("-n 20 --sensitivity /tmp/x.csv parts/cap.off", 2, "with a range");
    expect_failure("--mu 0.2:0.5 --sensitivity /tmp/x.csv parts/cap.off", 2, "needs drops");
    expect_failure("-n 20 --mu 0.2:0.5 --shard 1/2 --sensitivity /tmp/x.csv parts/cap.off", 2,
                   "--shard");
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0)
        printf("     could not remove %s\n", tmpdir);
}

void suite_sensitivity(void)
{
    test_command();
    test_given_data();
    test_records();
    test_effects();
    test_frictionless_belt();
}
