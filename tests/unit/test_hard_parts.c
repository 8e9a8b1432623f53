/* test_hard_parts.c: the hard-part corpus (docs/limits.md), generated here, on
 * every engine: shallow ridges, flat pyramids, needles, a tenth-of-a-
 * millimetre cube (which often ends up spinning on a corner, a top) and a
 * 1000 m one, a 1 mm cube released spinning (another top), a 64-gon coin
 * started on its rim, and knife-edge facets. Each part runs on the impulse engine, ODE and Bullet
 * with the default scene and options (the automatic time limit included),
 * and each run must have
 *   - no failed drop;
 *   - at most 0.5% of its drops unsettled;
 *   - the poses a rotation of the part maps onto each other (mirror-image
 *     facets: the roof's two halves, a needle's four sides, a coin's faces)
 *     sharing their drops within the binomial bound.
 * The cases that fail today are listed in expected_failures, with a nonzero
 * tag for the defect whose fix they wait for; such a case is checked the other
 * way, so that it fails the suite once it passes and the table cannot go
 * stale. It runs only until it fails (a failed drop, or more unsettled drops
 * than its full run allows: the full run would fail too), so the cases
 * waiting for a fix cost a few drops each, not their time limits. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "check.h"
#include "engine_steps.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "sim/drop.h"
#include "suites.h"
#include "base/vec3.h"

/* The sanitizer build runs every case, on fewer drops (but the expected
 * failures: case_drops): the checks keep their meaning at any count (the
 * binomial tails are exact at any count; 0.5% of fewer than 200
 * drops allows none). */
#if defined(__SANITIZE_ADDRESS__)
#define DROPS_SCALE 10
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DROPS_SCALE 10
#endif
#endif
#ifndef DROPS_SCALE
#define DROPS_SCALE 1
#endif

/* Unsettled drops allowed, as a share of the drops run (the bound). */
#define UNSETTLED_MAX 0.005
/* A member of a class of k symmetric poses holds a Binomial(N, 1/k) share
 * of the class's N drops (by symmetry each drop's pose is uniform over the
 * class); it is an outlier when the exact two-sided tail of its count is
 * below this. With ~480 members tested in all (the three engines), a false
 * alarm has odds below 0.5% (less still: discrete tails are conservative).
 * Exact tails, not a normal bound: a 64-gon's rim holds a few drops over 64
 * facets (means near 0.4), where the normal tail is far too thin (one facet
 * with 4 of 28 rim drops was 3.9 sigmas out, a 1-in-15 event for a rim). */
#define MIRROR_ALPHA 1e-5

typedef enum { RIDGE, PYRAMID, NEEDLE, CUBE, COIN, KNIFE } shape_kind;

typedef struct {
    const char *name;
    shape_kind kind;
    double a, b;    /* RIDGE: angle (deg); PYRAMID: height / radius; NEEDLE:
                       length (m), aspect; CUBE: edge (m), the scene's
                       tumble (rad/s) */
    long drops;     /* per engine in the optimized build: a few hundred where
                       a drop is cheap, fewer where the stepping engines take
                       thousands of steps per drop */
} hard_case;

static const hard_case cases[] = {
    {"ridge 0.1 deg", RIDGE, 0.1, 0, 200},
    {"ridge 0.3 deg", RIDGE, 0.3, 0, 200},
    {"ridge 0.9 deg", RIDGE, 0.9, 0, 200},
    {"ridge 2 deg", RIDGE, 2.0, 0, 200},
    {"ridge 5 deg", RIDGE, 5.0, 0, 200},
    {"pyramid h/r 1e-5", PYRAMID, 1e-5, 0, 200},
    {"pyramid h/r 1e-3", PYRAMID, 1e-3, 0, 200},
    {"pyramid h/r 1e-1", PYRAMID, 1e-1, 0, 200},
    {"needle 1 m x 100", NEEDLE, 1.0, 100, 100},
    {"needle 1 m x 300", NEEDLE, 1.0, 300, 100},
    {"needle 1 m x 1000", NEEDLE, 1.0, 1000, 100},
    {"needle 1 mm x 100", NEEDLE, 1e-3, 100, 100},
    {"needle 1 mm x 1000", NEEDLE, 1e-3, 1000, 100},
    {"cube 0.1 mm", CUBE, 1e-4, 0, 200},
    {"cube 1 mm spun at 3000 rad/s", CUBE, 1e-3, 3000, 100},
    {"cube 1000 m", CUBE, 1e3, 0, 20},
    {"coin 64-gon on its rim", COIN, 0, 0, 200},
    {"knife-edge prism", KNIFE, 0, 0, 200},
};
enum { NCASES = sizeof cases / sizeof cases[0] };

static const pd_engine_kind engines[] = {PD_ENGINE_IMPULSE, PD_ENGINE_ODE, PD_ENGINE_BULLET};
static const char *const engine_names[] = {"impulse", "ode", "bullet"};

/* The cases that fail today, each with a nonzero tag for the defect that is
 * to fix it. A case listed here must fail (one of its checks); one that passes is
 * reported as a failure, to be taken out of the table. The last line ends
 * the table. */
static const struct {
    const char *name;
    pd_engine_kind engine;
    int item;
} expected_failures[] = {
    {NULL, PD_ENGINE_IMPULSE, 0},
};

static int expected_item(const char *name, pd_engine_kind engine)
{
    for (int i = 0; expected_failures[i].name; i++)
        if (expected_failures[i].engine == engine && strcmp(expected_failures[i].name, name) == 0)
            return expected_failures[i].item;
    return 0;
}

/* The part of case c, or NULL with the library's refusal in diag. */
static pd_part *case_part(const hard_case *c, pd_diag *diag)
{
    pd_vec3 p[128];
    int n = 0;
    double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    switch (c->kind) {
    case RIDGE:
        return part_of(mesh_roof_box(0.02, 0.01, 0.01, c->a * M_PI / 180.0), NULL, diag);
    case PYRAMID: /* six sides, 1 cm across */
        n = pts_flat_pyramid(6, c->a, p);
        points_transform(p, n, CR(I), 0.005, v3(0, 0, 0));
        break;
    case NEEDLE:
        n = pts_box(c->a, c->a / c->b, c->a / c->b, p);
        break;
    case CUBE:
        n = pts_box(c->a, c->a, c->a, p);
        break;
    case COIN: /* 2 cm across, 2 mm thick */
        n = pts_prism(64, 0.01, 0.002, p);
        break;
    case KNIFE: /* 2 x 1 x 1 cm */
        n = pts_parallelogram_prism(p);
        points_transform(p, n, CR(I), 0.01, v3(0, 0, 0));
        break;
    }
    pd_part *part = NULL;
    return part_of_points(p, n, &part, diag) == PD_OK ? part : NULL;
}

/* The drops case c runs: a case expected to fail runs the optimized
 * build's count in any build (it stops at its failure, and a rare failure
 * needs the drops to show); others at least 10. */
static long case_drops(const hard_case *c, int expected)
{
    if (expected)
        return c->drops;
    return c->drops / DROPS_SCALE > 10 ? c->drops / DROPS_SCALE : 10;
}

/* Where drop i of case c starts: NULL for a uniform orientation, or (the
 * coin) the cumulative distribution resting on its rim, each side facet
 * alike (cdf: room for the poses). */
static const double *case_start(const hard_case *c, const pd_static_result *poses, double *cdf)
{
    if (c->kind != COIN)
        return NULL;
    int sides = 0;
    for (int k = 0; k < poses->nposes; k++)
        sides += fabs(poses->poses[k].normal.z) < 0.5;
    double acc = 0.0;
    for (int k = 0; k < poses->nposes; k++) {
        acc += fabs(poses->poses[k].normal.z) < 0.5 ? 1.0 / sides : 0.0;
        cdf[k] = acc;
    }
    cdf[poses->nposes - 1] = 1.0;
    return sides ? cdf : NULL;
}

typedef struct {
    long n, unsettled, failed, mirror_bad;
    long *count;
    pd_trial first_bad; /* the first drop that did not settle */
} case_run;

/* The drops of case c on engine e, one after another through the drop loop
 * every run uses (pd_drop_run, as pd_sim_run's threads call it); with
 * until_failed, only until a drop fails or more are unsettled than the run
 * allows. 0 (a check counted) if the model cannot be built; 2 if the engine
 * refuses the part up front (PD_ERR_UNAVAILABLE with the reason, which the
 * issue allows in place of drops), the reason in why. */
static int run_case(const hard_case *c, const pd_part *part, const pd_static_result *poses,
                    pd_engine_kind engine, int until_failed, case_run *out, pd_diag *why)
{
    pd_scene sc;
    pd_scene_default(&sc);
    if (c->kind == CUBE)
        sc.tumble = c->b;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    pd_sim_model *model = NULL;
    pd_diag_init(why);
    pd_status built = pd_sim_model_build(part, poses, &sc, &o, &model, why);
    if (built == PD_ERR_UNAVAILABLE && engine != PD_ENGINE_IMPULSE && why->message[0])
        return 2;
    CHECK_STATUS(built, PD_OK);
    pd_drop_work *w = model ? pd_drop_work_alloc(model, &sc) : NULL;
    CHECK(w != NULL);
    double *cdf = malloc(sizeof *cdf * (size_t)poses->nposes);
    out->count = calloc((size_t)poses->nposes, sizeof *out->count);
    if (!w || !cdf || !out->count) {
        pd_drop_work_free(w);
        pd_sim_model_free(model);
        free(cdf);
        return 0;
    }
    const double *start = case_start(c, poses, cdf);
    long n = case_drops(c, until_failed);
    for (long i = 0; i < n; i++) {
        if (until_failed && (out->failed > 0 || out->unsettled > UNSETTLED_MAX * (double)n))
            break;
        out->n++;
        pd_trial t;
        long gain = 0, fallbacks = 0;
        pd_drop_run(model, w, &sc, &o, i, start, &t, &gain, &fallbacks);
        if (t.end == PD_END_SETTLED && t.pose >= 0) {
            out->count[t.pose]++;
            continue;
        }
        if (out->unsettled++ == 0)
            out->first_bad = t;
        out->failed += t.end == PD_END_FAILED;
    }
    free(cdf);
    pd_drop_work_free(w);
    pd_sim_model_free(model);
    return 1;
}

/* P(X >= k) (upper) or P(X <= k) for X ~ Binomial(n, p), 0 < p < 1, summed
 * term by term from logs (n is a few hundred drops). */
static double binomial_tail(long n, double p, long k, int upper)
{
    double sum = 0.0;
    for (long j = upper ? k : 0; j <= (upper ? n : k); j++)
        sum += exp(lgamma((double)n + 1.0) - lgamma((double)j + 1.0) -
                   lgamma((double)(n - j) + 1.0) + (double)j * log(p) +
                   (double)(n - j) * log1p(-p));
    return sum;
}

/* Members of each class of poses a rotation maps onto each other whose
 * count's exact binomial two-sided tail is below MIRROR_ALPHA; *classes
 * counts the classes of two poses or more (every part of the corpus has
 * one, so the check is never empty). */
static long mirror_outliers(const pd_part *part, const pd_static_result *poses, const long *count,
                            int *classes)
{
    int *class_of = malloc(sizeof *class_of * (size_t)(poses->nposes + 1)), nclasses = 0;
    long bad = 0;
    if (!class_of || pd_pose_classes(part, poses, class_of, &nclasses, NULL) != PD_OK) {
        free(class_of);
        return -1;
    }
    for (int c = 0; c < nclasses; c++) {
        long total = 0;
        int members = 0;
        for (int k = 0; k < poses->nposes; k++)
            if (class_of[k] == c) {
                total += count[k];
                members++;
            }
        if (members < 2)
            continue;
        (*classes)++;
        double p = 1.0 / members;
        for (int k = 0; k < poses->nposes; k++) {
            if (class_of[k] != c)
                continue;
            double two_sided = 2.0 * fmin(binomial_tail(total, p, count[k], 1),
                                          binomial_tail(total, p, count[k], 0));
            bad += two_sided < MIRROR_ALPHA;
        }
    }
    free(class_of);
    return bad;
}

/* How a drop that did not settle ended, as --trials says it. */
static const char *end_word(const pd_trial *t)
{
    switch (t->end) {
    case PD_END_TIME_LIMIT: return "at the time limit";
    case PD_END_COLLISION_LIMIT: return "at the collision limit";
    default: return pd_drop_stage_name(t->stage);
    }
}

static void check_case(const hard_case *c, const pd_part *part, const pd_static_result *poses,
                       int e)
{
    case_run r = {0};
    clock_t t0 = clock();
    int item = expected_item(c->name, engines[e]);
    pd_diag why;
    int ran = run_case(c, part, poses, engines[e], item > 0, &r, &why);
    if (ran == 2) {
        pd_note("%-24s %-7s refused: %s\n", c->name, engine_names[e], why.message);
        if (item)
            printf("     %s on %s is refused: take it out of expected_failures "
                   "(tag %d)\n", c->name, engine_names[e], item);
        CHECK(!item);
        return;
    }
    if (!ran) {
        free(r.count);
        return;
    }
    int classes = 0;
    r.mirror_bad = mirror_outliers(part, poses, r.count, &classes);
    CHECK(classes > 0);
    long full = case_drops(c, item > 0);
    int no_failed = r.failed == 0, settled = r.unsettled <= UNSETTLED_MAX * (double)full,
        mirrored = r.mirror_bad == 0;
    pd_note("%-24s %-7s %ld drops: %ld unsettled (%ld failed), %ld poses outside the mirror "
            "bound; %.2f s CPU\n", c->name, engine_names[e], r.n, r.unsettled, r.failed,
            r.mirror_bad, (double)(clock() - t0) / CLOCKS_PER_SEC);
    if (item) {
        if (no_failed && settled && mirrored)
            printf("     %s on %s passes: take it out of expected_failures (tag %d)\n",
                   c->name, engine_names[e], item);
        CHECK(!(no_failed && settled && mirrored));
    } else {
        if (!(no_failed && settled && mirrored))
            printf("     %s on %s: %ld of %ld drops unsettled (%ld failed; the first ended %s "
                   "at %.6g s after %d collisions), %ld poses outside the mirror bound\n",
                   c->name, engine_names[e], r.unsettled, r.n, r.failed,
                   r.unsettled ? end_word(&r.first_bad) : "-",
                   r.unsettled ? r.first_bad.time : 0.0, r.unsettled ? r.first_bad.collisions : 0,
                   r.mirror_bad);
        CHECK(no_failed);
        CHECK(settled);
        CHECK(mirrored);
    }
    free(r.count);
}

/* Every name in the table is a case of the corpus, so a renamed case cannot
 * leave a stale line behind. */
static void test_table_names(void)
{
    for (int i = 0; expected_failures[i].name; i++) {
        int found = 0;
        for (int k = 0; k < NCASES; k++)
            found |= strcmp(expected_failures[i].name, cases[k].name) == 0;
        CHECK(found);
    }
}

void suite_hard_parts(void)
{
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    test_table_names();
    for (int k = 0; k < NCASES; k++) {
        pd_diag d;
        pd_diag_init(&d);
        pd_part *part = case_part(&cases[k], &d);
        pd_static_result *poses = NULL;
        if (part)
            CHECK_STATUS(pd_static_estimate(part, NULL, &poses, &d), PD_OK);
        if (!part || !poses) {
            printf("     %s: %s\n", cases[k].name, d.message);
            CHECK(part != NULL && poses != NULL);
        }
        for (int e = 0; poses && e < 3; e++)
            check_case(&cases[k], part, poses, e);
        pd_static_result_free(poses);
        pd_part_free(part);
    }
}
