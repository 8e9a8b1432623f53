/* test_markov.c: the long-run distribution of a pose-to-pose chain against
 * closed forms, its resampling intervals, and --initial stationary end to end
 * on the cube. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "check.h"
#include "base/gsl_adapter.h"
#include "sim/markov.h"
#include "posedrop/posedrop.h"
#include "posedrop/tolerances.h"
#include "shapes.h"
#include "suites.h"

/* pi of the k-state chain P from mu0; nclosed returned through *nc. */
static pd_status limit(int k, const double *P, const double *mu0, double *pi, int *nc)
{
    pd_markov_work *w = pd_markov_work_alloc(k);
    CHECK(w != NULL);
    pd_status st = w ? pd_markov_limit(w, P, mu0, pi, nc) : PD_ERR_NOMEM;
    pd_markov_work_free(w);
    return st;
}

/* Round-off of a few eliminations on probabilities of order 1. */
static const double ROUND = 1e-15;

static void test_closed_forms(void)
{
    double pi[6];
    int nc;

    /* Two states, leaving at rates a and b: pi = (b, a) / (a + b), whatever
     * mu0 (irreducible). */
    const double a = 0.3, b = 0.05;
    const double two[] = {1 - a, a, b, 1 - b}, start[] = {1, 0};
    CHECK_STATUS(limit(2, two, start, pi, &nc), PD_OK);
    CHECK_INT(nc, 1);
    CHECK_NEAR(pi[0], b / (a + b), ROUND, "closed form");
    CHECK_NEAR(pi[1], a / (a + b), ROUND, "closed form");

    /* Period 2: mu0 P^t swings between (1, 0) and (0, 1) for ever; its
     * Cesaro mean is (1/2, 1/2). */
    const double swap[] = {0, 1, 1, 0};
    CHECK_STATUS(limit(2, swap, start, pi, &nc), PD_OK);
    CHECK_INT(nc, 1);
    CHECK_NEAR(pi[0], 0.5, 0.0, "closed form, exact in binary");
    CHECK_NEAR(pi[1], 0.5, 0.0, "closed form, exact in binary");

    /* Reducible: 0 and 3 absorb; 1 goes to 0 or 2 by halves, 2 to 1 with
     * 1/3 and to 3 with 2/3. Absorption into 0: h1 = 1/2 + h2/2,
     * h2 = h1/3, so h1 = 3/5, h2 = 1/5; from mu0 = (.1, .4, .3, .2),
     * pi0 = .1 + .4 (3/5) + .3 (1/5) = .4 and pi3 = .6. */
    const double gambler[] = {1, 0, 0, 0, 0.5, 0, 0.5, 0, 0, 1.0 / 3, 0, 2.0 / 3, 0, 0, 0, 1};
    const double mu4[] = {0.1, 0.4, 0.3, 0.2};
    CHECK_STATUS(limit(4, gambler, mu4, pi, &nc), PD_OK);
    CHECK_INT(nc, 2);
    CHECK_NEAR(pi[0], 0.4, 4 * ROUND, "absorption probabilities by hand");
    CHECK_NEAR(pi[1], 0.0, 0.0, "transient");
    CHECK_NEAR(pi[2], 0.0, 0.0, "transient");
    CHECK_NEAR(pi[3], 0.6, 4 * ROUND, "absorption probabilities by hand");
    /* Started on 0 alone, 3 is never reached: one closed class. */
    const double on0[] = {1, 0, 0, 0};
    CHECK_STATUS(limit(4, gambler, on0, pi, &nc), PD_OK);
    CHECK_INT(nc, 1);
    CHECK(pi[0] == 1 && pi[3] == 0);

    /* The identity: nothing moves, every state its own class, pi = mu0. */
    double I[16] = {0};
    for (int i = 0; i < 4; i++)
        I[i * 5] = 1;
    CHECK_STATUS(limit(4, I, mu4, pi, &nc), PD_OK);
    CHECK_INT(nc, 4);
    for (int i = 0; i < 4; i++)
        CHECK_NEAR(pi[i], mu4[i], ROUND, "pi = mu0");

    /* Rows of states mu0 never reaches are not read, even empty ones; a
     * reached empty row is refused. */
    const double holes[] = {0.5, 0.5, 0, 0.5, 0.5, 0, 0, 0, 0};
    CHECK_STATUS(limit(3, holes, (const double[]){1, 0, 0}, pi, &nc), PD_OK);
    CHECK_NEAR(pi[0], 0.5, 0.0, "closed form");
    CHECK_STATUS(limit(3, holes, (const double[]){0, 0, 1}, pi, &nc), PD_ERR_USAGE);
}

static void test_random_chains(void)
{
    /* Random 6 x 6 stochastic matrices, dense and with zeros: pi P = pi and
     * pi sums to 1, to round-off of sums of 6 products. */
    test_rng r = {42};
    for (int trial = 0; trial < 50; trial++) {
        double P[36], mu0[6], pi[6];
        for (int i = 0; i < 6; i++) {
            double s = 0;
            for (int j = 0; j < 6; j++) {
                double u = rng_uniform(&r);
                P[i * 6 + j] = trial % 2 && u < 0.4 ? 0.0 : u;
                s += P[i * 6 + j];
            }
            if (s == 0)
                P[i * 6 + i] = s = 1;
            for (int j = 0; j < 6; j++)
                P[i * 6 + j] /= s;
        }
        /* mu0 on a single state, so pi P = pi holds for the class it
         * reaches even when the chain is reducible. */
        for (int i = 0; i < 6; i++)
            mu0[i] = i == trial % 6;
        int nc;
        CHECK_STATUS(limit(6, P, mu0, pi, &nc), PD_OK);
        double worst = 0, sum = 0;
        for (int j = 0; j < 6; j++) {
            double v = 0;
            for (int i = 0; i < 6; i++)
                v += pi[i] * P[i * 6 + j];
            worst = fmax(worst, fabs(v - pi[j]));
            sum += pi[j];
        }
        CHECK_NEAR(worst, 0.0, 1e-12, "stationary, round-off");
        CHECK_NEAR(sum, 1.0, 1e-15, "a distribution, round-off");
        CHECK(nc >= 1);
    }

    /* Probabilities 1e-12 apart keep full relative accuracy (no
     * subtraction): two states leaving at 1e-12 and 1e-24 hold
     * pi = (1e-24, 1e-12) / (1e-12 + 1e-24). */
    const double stiff[] = {1 - 1e-12, 1e-12, 1e-24, 1 - 1e-24};
    double pi[2];
    int nc;
    CHECK_STATUS(limit(2, stiff, (const double[]){0.5, 0.5}, pi, &nc), PD_OK);
    CHECK_REL(pi[0], 1e-24 / (1e-12 + 1e-24), 1e-15, "closed form, relative round-off");
}

static void test_estimate(void)
{
    /* Counts of a 3-pose part: pose 2 (index 2) is never reached from the
     * uniform drops' outcomes, and its row is empty. */
    const long first[] = {30, 10, 0};
    const long C[] = {60, 40, 0, 20, 80, 0, 0, 0, 0};
    pd_markov_counts counts = {3, first, C};
    double p[3], lo[3], hi[3];
    pd_markov_summary s = {p, lo, hi, 0, 0};
    CHECK_STATUS(pd_markov_estimate(&counts, NULL, 3, 7, &s), PD_OK);
    CHECK_INT(s.nclosed, 1);
    /* P = [.6 .4; .2 .8]: pi = (.2, .4) / .6 = (1/3, 2/3). */
    CHECK_NEAR(p[0], 1.0 / 3, ROUND, "closed form");
    CHECK_NEAR(p[1], 2.0 / 3, ROUND, "closed form");
    CHECK(p[2] == 0 && lo[2] == 0 && hi[2] == 0);
    CHECK_NEAR(s.shift, 0.75 - 1.0 / 3, ROUND, "TV of (3/4, 1/4) and (1/3, 2/3)");
    /* The interval holds the estimate, and is about as wide as the delta
     * method says: pi0 = b / (a + b) with a = 40/100 and b = 20/100 has
     * variance (b^2 var a + a^2 var b) / (a + b)^4 = 0.0027, a standard
     * error of 0.052, a 95% half-width of 0.102. */
    CHECK(lo[0] < p[0] && p[0] < hi[0] && lo[1] < p[1] && p[1] < hi[1]);
    CHECK_NEAR(0.5 * (hi[0] - lo[0]), 0.102, 0.02,
               "delta method (first order at 100 drops a row); the ends' own Monte Carlo "
               "error is ~0.005");
    /* Same counts and seed: the same bytes. Another seed: other redraws. */
    double p2[3], lo2[3], hi2[3];
    pd_markov_summary s2 = {p2, lo2, hi2, 0, 0};
    CHECK_STATUS(pd_markov_estimate(&counts, NULL, 3, 7, &s2), PD_OK);
    CHECK(memcmp(lo, lo2, sizeof lo) == 0 && memcmp(hi, hi2, sizeof hi) == 0);
    CHECK_STATUS(pd_markov_estimate(&counts, NULL, 3, 8, &s2), PD_OK);
    CHECK(memcmp(lo, lo2, sizeof lo) != 0);

    /* Classes: poses 0 and 1 together hold everything. */
    const int class_of[] = {0, 0, 1};
    double pc[2], loc[2], hic[2];
    pd_markov_summary sc = {pc, loc, hic, 0, 0};
    CHECK_STATUS(pd_markov_estimate(&counts, class_of, 2, 7, &sc), PD_OK);
    CHECK_NEAR(pc[0], 1.0, ROUND, "sum of the class");
    CHECK_NEAR(loc[0], 1.0, ROUND, "every redraw sums to 1");

    /* A reached pose without a settled drop started on it: not defined,
     * reported as nclosed = 0 with the outputs untouched. */
    const long C2[] = {60, 30, 10, 20, 80, 0, 0, 0, 0};
    pd_markov_counts gap = {3, first, C2};
    p[0] = -1;
    CHECK_STATUS(pd_markov_estimate(&gap, NULL, 3, 7, &s), PD_OK);
    CHECK_INT(s.nclosed, 0);
    CHECK(p[0] == -1);
    /* Nor without a settled uniform drop. */
    const long none[] = {0, 0, 0};
    pd_markov_counts nofirst = {3, none, C};
    CHECK_STATUS(pd_markov_estimate(&nofirst, NULL, 3, 7, &s), PD_OK);
    CHECK_INT(s.nclosed, 0);

    /* The multinomial draws sum to their total. */
    pd_rng rng;
    pd_rng_init(&rng, 1, 2);
    unsigned out[4];
    pd_gsl_multinomial(&rng, 4, 1000, (const double[]){1, 0, 3, 6}, out);
    CHECK_INT(out[0] + out[1] + out[2] + out[3], 1000);
    CHECK_INT(out[1], 0);
}

/* One outcome drawn from the distribution p (k entries). */
static int draw_pose(test_rng *r, const double *p, int k)
{
    double u = rng_uniform(r), acc = 0;
    for (int j = 0; j < k; j++)
        if (u < (acc += p[j]))
            return j;
    return k - 1;
}

static void test_coverage(void)
{
    /* A pose kept 97% of the time, estimated from 20 drops per row: the
     * 95% intervals must hold the true pi in at least 90% of 200 repeated
     * estimates (binomial spread of 200 repetitions at 95%: 1.5%, so 90%
     * is 3 spreads below nominal). Redrawn from the counts alone they held
     * it in 47% (tolerances.h, PD_STATIONARY_PSEUDO_DROPS). */
    const double P[] = {0.97, 0.02, 0.01, 0.5, 0.3, 0.2, 0.4, 0.4, 0.2};
    const double mu0[] = {0.3, 0.4, 0.3};
    double pi[3];
    int nc;
    CHECK_STATUS(limit(3, P, mu0, pi, &nc), PD_OK);
    enum { REPS = 200, M = 20 };
    int held[3] = {0}, defined = 0, holds_p = 1;
    test_rng r = {2024};
    for (int rep = 0; rep < REPS; rep++) {
        long first[3] = {0}, C[9] = {0};
        for (int d = 0; d < M; d++)
            first[draw_pose(&r, mu0, 3)]++;
        for (int i = 0; i < 3; i++)
            for (int d = 0; d < M; d++)
                C[i * 3 + draw_pose(&r, P + i * 3, 3)]++;
        pd_markov_counts counts = {3, first, C};
        double p[3], lo[3], hi[3];
        pd_markov_summary s = {p, lo, hi, 0, 0};
        CHECK_STATUS(pd_markov_estimate(&counts, NULL, 3, (uint64_t)rep, &s), PD_OK);
        defined += s.nclosed > 0;
        for (int j = 0; s.nclosed > 0 && j < 3; j++) {
            held[j] += lo[j] <= pi[j] && pi[j] <= hi[j];
            holds_p &= lo[j] <= p[j] && p[j] <= hi[j];
        }
    }
    CHECK_INT(defined, REPS);
    for (int j = 0; j < 3; j++)
        CHECK(held[j] >= 0.90 * REPS);
    CHECK(holds_p);
}

/* --- end to end ----------------------------------------------------------- */

static pd_sim_result *run_stationary(const pd_part *part, const pd_static_result *poses,
                                     long n, int threads)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.initial = PD_INITIAL_STATIONARY;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = n;
    o.threads = threads;
    o.seed = 11;
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_sim_run(part, poses, &sc, &o, &r, &d);
    if (st != PD_OK)
        printf("     pd_sim_run: %s (%s)\n", pd_status_str(st), d.message);
    return r;
}

static atomic_int stop_flag;

static void *stop_soon(void *arg)
{
    (void)arg;
    struct timespec ts = {0, 300000000};
    nanosleep(&ts, NULL);
    atomic_store(&stop_flag, 1);
    return NULL;
}

/* A run interrupted long before its uniform share is done (7e6 drops, of
 * which 1e6 uniform) still has drops of every phase, in proportion: the
 * phases are interleaved from the first drop. Whenever the stop comes, each
 * pose's row holds floor(n/7) or ceil(n/7) started drops, less any
 * unsettled ones; it used to hold none until the uniform drops were done. */
static void test_interrupted(const pd_part *part, const pd_static_result *poses)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.initial = PD_INITIAL_STATIONARY;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 7000000;
    o.threads = 2;
    atomic_store(&stop_flag, 0);
    o.cancel = &stop_flag;
    pthread_t t;
    CHECK(pthread_create(&t, NULL, stop_soon, NULL) == 0);
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_OK);
    pthread_join(t, NULL);
    CHECK(r != NULL);
    if (!r)
        return;
    CHECK(r->partial == 1 && r->n < o.ndrops);
    int in_share = 1;
    long firsts = 0;
    for (int i = 0; i < 6; i++) {
        long row = 0;
        for (int j = 0; j < 6; j++)
            row += r->transitions[i * 6 + j];
        in_share &= row >= r->n / 7 - r->unsettled && row <= (r->n + 6) / 7;
        firsts += r->first_count[i];
    }
    CHECK(in_share);
    CHECK(firsts >= r->n / 7 - r->unsettled && firsts <= (r->n + 6) / 7);
    pd_sim_result_free(r);
}

static void test_cube(void)
{
    pd_diag d;
    pd_diag_init(&d);
    pd_mesh *m = NULL;
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    CHECK_STATUS(pd_mesh_read("parts/canonical/cube.off", NULL, &m, &d), PD_OK);
    part = part_of(m, NULL, &d);
    if (!part || pd_static_estimate(part, NULL, &poses, &d) != PD_OK) {
        CHECK(0);
        pd_part_free(part);
        return;
    }
    CHECK_INT(poses->nposes, 6);
    /* 700 drops: 100 uniform, 100 resting on each face. */
    pd_sim_result *a = run_stationary(part, poses, 700, 1);
    pd_sim_result *b = run_stationary(part, poses, 700, 2);
    CHECK(a && b);
    if (a && b) {
        CHECK_INT(a->n, 700);
        CHECK_INT(a->first_drops, 100);
        CHECK_INT(a->pose_drops, 100);
        CHECK_INT(a->unsettled, 0);
        /* Every drop of phase 2 is one transition (none unsettled). */
        long moves = 0, firsts = 0;
        for (int i = 0; i < 36; i++)
            moves += a->transitions[i];
        for (int i = 0; i < 6; i++)
            firsts += a->first_count[i];
        CHECK_INT(moves, 600);
        CHECK_INT(firsts, 100);
        CHECK(a->closed_classes >= 1);
        /* Threads change no byte. */
        CHECK(memcmp(a->p, b->p, 6 * sizeof *a->p) == 0);
        CHECK(memcmp(a->ci_lo, b->ci_lo, 6 * sizeof *a->ci_lo) == 0);
        CHECK(memcmp(a->ci_hi, b->ci_hi, 6 * sizeof *a->ci_hi) == 0);
        CHECK(memcmp(a->transitions, b->transitions, 36 * sizeof *a->transitions) == 0);
        /* The counts over both phases are uniform within the 99.9%
         * chi-square bound: each phase-2 row is a permutation of one
         * distribution, which makes the test conservative. */
        CHECK(uniform_p_value(a) > 1e-3);
        /* pi uniform: each pose's deviation from 1/6 over its resampled
         * standard error (the 95% half-width / 1.96), squared and summed,
         * within the 99.9% bound of chi-square with 6 degrees of freedom
         * (conservative: the sum to one takes one away). */
        double x2 = 0, sum = 0;
        for (int k = 0; k < 6; k++) {
            double se = (a->ci_hi[k] - a->ci_lo[k]) / (2 * 1.959963984540054);
            x2 += (a->p[k] - 1.0 / 6) * (a->p[k] - 1.0 / 6) / (se * se);
            sum += a->p[k];
        }
        CHECK(pd_gsl_chisq_q(x2, 6) > 1e-3);
        for (int k = 0; k < 6; k++)
            CHECK(a->ci_lo[k] <= a->p[k] && a->p[k] <= a->ci_hi[k]);
        CHECK_NEAR(sum, 1.0, 1e-15, "a distribution, round-off");
    }
    pd_sim_result_free(a);
    pd_sim_result_free(b);
    test_interrupted(part, poses);

    /* Too few drops for the poses: refused with the minimum named. */
    pd_scene sc;
    pd_scene_default(&sc);
    sc.initial = PD_INITIAL_STATIONARY;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.ndrops = 7 * PD_STATIONARY_MIN_POSE_DROPS - 1;
    pd_sim_result *r = NULL;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_ERR_USAGE);
    CHECK(r == NULL && strstr(d.message, "70") != NULL);
    /* --ci has no meaning for a split fixed in advance. */
    o.ndrops = 700;
    o.ci_halfwidth = 0.05;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_ERR_USAGE);

    /* Cancelled before the first drop: partial, raw counts, no NaN. */
    pd_sim_options_default(&o);
    o.ndrops = 700;
    atomic_int stop = 1;
    o.cancel = &stop;
    r = NULL;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_OK);
    CHECK(r && r->partial && r->n == 0 && r->closed_classes == 0);
    if (r)
        for (int k = 0; k < 6; k++)
            CHECK(r->p[k] == 0 && r->ci_lo[k] == 0 && r->ci_hi[k] == 1);
    pd_sim_result_free(r);
    pd_static_result_free(poses);
    pd_part_free(part);
}

/* The chain of classes of symmetric poses (stationary_by_class): on a coin
 * of height half its diameter, whose 66 poses fall into 2 classes (the faces,
 * the rim's 64 sides) and whose chain moves between them, its long-run
 * distribution is the pose chain's summed over the classes (lumpability), so
 * the two estimates of each class agree within their drops' noise; each pose
 * gets an equal part of its class; the rows rest on n / 3 drops; threads
 * change no byte; and what cannot use it is refused. */
static void test_by_class(void)
{
    enum { K = 66 };
    pd_diag d;
    pd_diag_init(&d);
    pd_mesh *m = NULL;
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    CHECK_STATUS(pd_mesh_read("parts/canonical/coin_h0.5.off", NULL, &m, &d), PD_OK);
    part = part_of(m, NULL, &d);
    if (!part || pd_static_estimate(part, NULL, &poses, &d) != PD_OK || poses->nposes != K) {
        CHECK(0);
        pd_static_result_free(poses);
        pd_part_free(part);
        return;
    }
    int class_of[K], nc = 0;
    CHECK_STATUS(pd_pose_classes(part, poses, class_of, &nc, &d), PD_OK);
    CHECK_INT(nc, 2);
    pd_scene sc;
    pd_scene_default(&sc);
    sc.initial = PD_INITIAL_STATIONARY;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.seed = 11;
    o.ndrops = 900;
    o.stationary_by_class = 1;
    pd_sim_result *a = NULL, *b = NULL, *poses_chain = NULL;
    o.threads = 1;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &a, &d), PD_OK);
    o.threads = 2;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &b, &d), PD_OK);
    pd_sim_options q = o;
    q.stationary_by_class = 0;
    q.ndrops = 2010; /* 30 drops a pose */
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &q, &poses_chain, &d), PD_OK);
    if (a && b && poses_chain) {
        CHECK_INT(a->chain_states, 2);
        CHECK_INT(a->pose_drops, 300);
        CHECK_INT(a->first_drops, 300);
        CHECK(a->closed_classes >= 1);
        long moves = 0, firsts = a->first_count[0] + a->first_count[1];
        for (int i = 0; i < 4; i++)
            moves += a->transitions[i];
        /* Every settled drop is one count of its phase. */
        CHECK_INT(moves + firsts, 900 - a->unsettled);
        CHECK(memcmp(a->p, b->p, K * sizeof *a->p) == 0);
        CHECK(memcmp(a->transitions, b->transitions, 4 * sizeof *a->transitions) == 0);
        double pc[2][2] = {{0}}, sd[2][2] = {{0}}, sum = 0;
        for (int j = 0; j < K; j++) {
            for (int i = 0; i < K; i++)
                if (class_of[i] == class_of[j])
                    CHECK_NEAR(a->p[j], a->p[i], 1e-15, "a class's share split equally");
            CHECK(a->ci_lo[j] <= a->p[j] && a->p[j] <= a->ci_hi[j]);
            sum += a->p[j];
            const pd_sim_result *r[2] = {a, poses_chain};
            for (int e = 0; e < 2; e++) {
                pc[e][class_of[j]] += r[e]->p[j];
                /* Each pose's error taken as fully correlated within its
                 * class: the larger, conservative, standard error. */
                sd[e][class_of[j]] += (r[e]->ci_hi[j] - r[e]->ci_lo[j]) / (2 * 1.959963984540054);
            }
        }
        CHECK_NEAR(sum, 1.0, 1e-12, "a distribution, round-off");
        CHECK(pc[0][0] > 0.05 && pc[0][1] > 0.05); /* a chain that moves */
        /* The first class's difference over its standard error within the
         * 99.9% normal bound (the second is its complement). */
        double z = (pc[0][0] - pc[1][0]) / sqrt(sd[0][0] * sd[0][0] + sd[1][0] * sd[1][0]);
        CHECK(fabs(z) < 3.29);
        pd_note("class chain: %.3f %.3f (900 drops); pose chain: %.3f %.3f (2010): z %.2f\n",
                pc[0][0], pc[0][1], pc[1][0], pc[1][1], z);
    }
    pd_sim_result_free(a);
    pd_sim_result_free(b);
    pd_sim_result *g = NULL;
    if (poses_chain)
        CHECK_STATUS(pd_sim_result_grouped(poses_chain, class_of, nc, &g, &d), PD_OK);
    pd_sim_result_free(g);
    pd_sim_result_free(poses_chain);
    /* The minimum is per class: (2 + 1) 10 drops. */
    o.ndrops = 3 * PD_STATIONARY_MIN_POSE_DROPS - 1;
    pd_sim_result *r = NULL;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_ERR_USAGE);
    CHECK(r == NULL && strstr(d.message, " 30 ") != NULL && strstr(d.message, "classes"));
    /* Not for shards, nor a sum of them. */
    o.ndrops = 900;
    o.nshards = 2;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_ERR_USAGE);
    o.nshards = 0;
    CHECK_STATUS(pd_sim_result_new(poses, &sc, &o, &r, &d), PD_ERR_USAGE);
    o.stationary_by_class = 2;
    CHECK_STATUS(pd_sim_run(part, poses, &sc, &o, &r, &d), PD_ERR_USAGE);
    CHECK(r == NULL);
    pd_static_result_free(poses);
    pd_part_free(part);
}

void suite_markov(void)
{
    test_closed_forms();
    test_random_chains();
    test_estimate();
    test_coverage();
    test_cube();
    test_by_class();
}
