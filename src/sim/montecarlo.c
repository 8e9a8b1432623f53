/* montecarlo.c: running many drops on all cores, deterministically.
 *
 * Work is cut into batches of drop indices. Within a batch, threads take
 * indices from a shared counter and write each outcome at its index; the
 * batch is tallied in index order after all threads finish. Each drop's
 * randomness comes from its own stream (seed, index), so neither the thread
 * count nor the scheduling can change a byte of the result. What depends on
 * earlier outcomes (the bootstrap's initial distribution, the --ci stopping
 * rule) is decided between batches, on tallies of whole batches only; the
 * stationary estimator's phases depend on nothing but the drop index. A
 * shard runs every nshards-th drop of the run (pd_shard_of): its batches hold
 * its own drops, each run under its index in the whole run. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "base/fail.h"
#include "base/hash.h"
#include "sim/drop.h"
#include "sim/markov.h"
#include "sim/scene.h"
#include "posedrop/sensitivity.h"
#include "posedrop/symmetry.h"
#include "sim/sim_tol.h"
#include "posedrop/tolerances.h"
#include "base/stats.h"
#include "static/static_check.h"

/* The paper's bootstrap: 20 uniform drops, then drops resting on poses drawn
 * from the running estimate. Rounds of fixed size keep it deterministic; the
 * estimate is updated between rounds. */
enum { BOOTSTRAP_FIRST = 20, BOOTSTRAP_ROUND = 100 };
/* --ci: drops between checks of the stopping rule. Plain runs go in batches
 * of at most BATCH_MAX, so the outcome buffer stays small for any -n. */
enum { CI_BATCH = 1000, BATCH_MAX = 65536 };
/* Two-sided 95% normal quantile for the Wilson intervals. */
static const double Z95 = PD_Z95;

void pd_sim_options_default(pd_sim_options *o)
{
    if (!o)
        return;
    memset(o, 0, sizeof *o);
    o->engine = PD_ENGINE_IMPULSE;
    o->dt = 0.0;
    o->ndrops = 2000;
    o->seed = 1;
    o->threads = 0;
    o->ci_halfwidth = 0.0;
    o->max_drops = 10000000;
    o->time_limit = PD_TIME_LIMIT_AUTO;
    o->max_collisions = 100000;
    o->keep_trials = 0;
    o->cancel = NULL;
    o->nshards = 0;
    o->shard = 0;
    o->progress = NULL;
    o->progress_user = NULL;
    o->trace = NULL;
    o->trace_user = NULL;
    o->trace_drop = 0;
}

double pd_time_limit_auto(double size, const pd_scene *scene)
{
    pd_scene def;
    if (!scene) {
        pd_scene_default(&def);
        scene = &def;
    }
    /* A drop height drawn from a range: its highest, the longest fall. */
    const pd_dist *h = &scene->range[PD_PARAM_HEIGHT];
    double g = scene->gravity, height = h->kind == PD_DIST_FIXED ? scene->height : h->hi;
    return PD_TIME_LIMIT_UNITS * (sqrt(size / g) + sqrt(2.0 * height / g));
}

const char *pd_drop_stage_name(pd_drop_stage stage)
{
    static const char *const names[PD_STAGE_COUNT] = {
        [PD_STAGE_NONE] = "none",
        [PD_STAGE_SETTLE] = "settle",
        [PD_STAGE_FLIGHT] = "flight",
        [PD_STAGE_IMPACT_SEARCH] = "impact_search",
        [PD_STAGE_COLLISION] = "collision",
        [PD_STAGE_COMPLIANT] = "compliant",
        [PD_STAGE_CONTACT_PHASE] = "contact_phase",
        [PD_STAGE_ENGINE_RESET] = "engine_reset",
        [PD_STAGE_ENGINE_STEP] = "engine_step",
    };
    return (unsigned)stage < PD_STAGE_COUNT ? names[stage] : "unknown";
}

int pd_shard_of(long drop, int nshards)
{
    if (drop < 0)
        return -1;
    return nshards > 0 ? (int)(drop % nshards) : 0;
}

long pd_shard_drops(long ndrops, int shard, int nshards)
{
    if (ndrops < 0)
        return 0;
    if (nshards <= 0)
        return ndrops;
    if (shard < 0 || shard >= nshards)
        return 0;
    /* The drops shard, shard + nshards, ... below ndrops; no sum that
     * could pass LONG_MAX. */
    return ndrops > shard ? (ndrops - shard - 1) / nshards + 1 : 0;
}

/* The run's index of a shard's drop number local. */
static long run_index(const pd_sim_result *r, long local)
{
    return r->nshards > 0 ? r->shard + local * r->nshards : local;
}

void pd_sim_result_free(pd_sim_result *r)
{
    if (!r)
        return;
    free(r->count);
    free(r->p);
    free(r->ci_lo);
    free(r->ci_hi);
    free(r->trials);
    free(r->first_count);
    free(r->transitions);
    free(r->chain_class_of);
    free(r->added);
    free(r);
}

typedef struct batch {
    const pd_sim_model *model;
    const pd_scene *scene;
    const pd_sim_options *opt;
    const double *init_cdf;
    const double *pose_cdfs; /* not NULL: drop i starts resting on pose
                               pd_stationary_start(i, ...) when it is one, whose
                               point-mass cdf is that row of pose_cdfs (instead
                               of init_cdf) */
    long pose_drops;
    int nposes;             /* the chain's states (pd_stationary_start's k) */
    const int *state_first, *state_poses; /* with pose_cdfs: state s's poses are
                               state_poses[state_first[s] .. state_first[s + 1]) */
    const pd_sim_result *r; /* its shard (run_index) */
    long first, last;       /* the shard's drop numbers [first, last) */
    pd_trial *out;          /* out[i - first] */
    long planned;           /* drops the run plans, for progress reports */
    pthread_t caller;       /* the thread that reports progress */
    atomic_long next;
    atomic_long done;
    atomic_long energy_gain;
    atomic_long fallbacks;
    atomic_int failed;      /* a thread could not get its work area */
} batch;

/* C11 lets a signal handler touch an atomic object only if it is lock-free,
 * and the CLI sets the flag from its SIGINT handler. */
_Static_assert(ATOMIC_INT_LOCK_FREE == 2, "the cancel flag must be a lock-free atomic_int");

/* --initial stationary: where drop i starts, -1 for a uniform orientation or
 * the pose it rests on. The first (k+1) pose_drops drops go round uniform,
 * pose 0, ..., pose k-1; the rest (fewer than k+1) are uniform. Interleaved
 * from the first drop, so a run stopped at any point has drops of every
 * phase in proportion. */
int pd_stationary_start(long i, long pose_drops, int k)
{
    if (i >= (long)(k + 1) * pose_drops)
        return -1;
    return (int)(i % (k + 1)) - 1;
}

static void *worker(void *arg)
{
    batch *b = arg;
    pd_drop_work *w = pd_drop_work_alloc(b->model, b->scene);
    if (!w) {
        atomic_store(&b->failed, 1);
        return NULL;
    }
    long gain = 0, fallbacks = 0;
    for (;;) {
        long i = atomic_fetch_add(&b->next, 1);
        if (i >= b->last || pd_drop_cancelled(b->opt))
            break;
        long drop = run_index(b->r, i);
        const double *cdf = b->init_cdf;
        int pose = b->pose_cdfs ? pd_stationary_start(drop, b->pose_drops, b->nposes) : -1;
        if (pose >= 0) {
            /* A state's drops go round its poses. */
            int first = b->state_first[pose], size = b->state_first[pose + 1] - first;
            pose = b->state_poses[first + (int)((drop / (b->nposes + 1)) % size)];
            cdf = b->pose_cdfs + (size_t)b->r->nposes * (size_t)pose;
        }
        /* The drop's own scene values: its ranges drawn from the parameters'
         * stream, which leaves the drop's orientation stream as it is. */
        pd_trial *out = &b->out[i - b->first];
        pd_scene drawn;
        pd_scene_draw(b->scene, b->model->part_size, b->opt->seed, drop, out->param, &drawn);
        if (pd_drop_material(b->model, w, &drawn) != PD_OK) {
            out->end = PD_END_FAILED;
        } else {
            pd_drop_run(b->model, w, &drawn, b->opt, drop, cdf, out, &gain, &fallbacks);
        }
        long done = atomic_fetch_add(&b->done, 1) + 1;
        if (b->opt->progress && pthread_equal(pthread_self(), b->caller))
            b->opt->progress(b->opt->progress_user, b->r->n + done, b->planned);
    }
    atomic_fetch_add(&b->energy_gain, gain);
    atomic_fetch_add(&b->fallbacks, fallbacks);
    pd_drop_work_free(w);
    return NULL;
}

/* Runs drops [first, last) into out; returns the number completed in index
 * order before any cancellation (a cancelled batch keeps its prefix only, so
 * that a partial result is still the first n drops of the run). */
static long run_batch(batch *b, int nthreads, pd_sim_result *r)
{
    atomic_store(&b->next, b->first);
    atomic_store(&b->done, 0);
    b->caller = pthread_self();
    atomic_store(&b->energy_gain, 0);
    atomic_store(&b->fallbacks, 0);
    atomic_store(&b->failed, 0);
    /* Zeroed first, padding included, so records compare byte for byte. */
    memset(b->out, 0, sizeof *b->out * (size_t)(b->last - b->first));
    for (long i = 0; i < b->last - b->first; i++)
        b->out[i].end = PD_END_NOT_RUN;
    pthread_t tid[256];
    int started = 0;
    for (int t = 1; t < nthreads; t++)
        if (pthread_create(&tid[started], NULL, worker, b) == 0)
            started++;
    worker(b); /* the calling thread works too */
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    r->energy_gain += atomic_load(&b->energy_gain);
    r->fallbacks += atomic_load(&b->fallbacks);
    long done = 0;
    while (b->first + done < b->last && b->out[done].end != PD_END_NOT_RUN)
        done++;
    return atomic_load(&b->failed) && done < b->last - b->first ? -1 : done;
}

/* Counts drops r->n .. r->n + n - 1, whose records are t[0..n). The
 * stationary estimator also files each settled drop under its phase: mu0's
 * counts, or the row of the pose it started on. */
static void tally(pd_sim_result *r, const pd_trial *t, long n)
{
    for (long i = 0; i < n; i++) {
        r->collisions += t[i].collisions;
        if (t[i].end != PD_END_SETTLED || t[i].pose < 0) {
            r->unsettled++;
            if (t[i].end == PD_END_TIME_LIMIT)
                r->time_limited++;
            else if (t[i].end == PD_END_COLLISION_LIMIT)
                r->collision_limited++;
            else if (r->failed++ == 0) {
                r->first_failed = run_index(r, r->n + i);
                r->failed_stage = t[i].stage;
                r->failed_status = t[i].status;
            }
            continue;
        }
        r->count[t[i].pose]++;
        if (!r->transitions)
            continue;
        int states = r->chain_class_of ? r->chain_states : r->nposes;
        int from = pd_stationary_start(run_index(r, r->n + i), r->pose_drops, states);
        int to = r->chain_class_of ? r->chain_class_of[t[i].pose] : t[i].pose;
        if (from < 0)
            r->first_count[to]++;
        else
            r->transitions[(size_t)from * (size_t)states + (size_t)to]++;
    }
    r->n += n;
}

/* Cumulative distribution of the settled outcomes so far (bootstrap). */
static void estimate_cdf(const pd_sim_result *r, double *cdf)
{
    long settled = 0;
    for (int k = 0; k < r->nposes; k++)
        settled += r->count[k];
    double acc = 0.0;
    for (int k = 0; k < r->nposes; k++) {
        acc += settled ? (double)r->count[k] / (double)settled : 1.0 / r->nposes;
        cdf[k] = acc;
    }
    cdf[r->nposes - 1] = 1.0;
}

static int ci_reached(const pd_sim_result *r, double delta)
{
    for (int k = 0; k < r->nposes; k++) {
        double lo, hi;
        pd_wilson(r->count[k], r->n, Z95, &lo, &hi);
        double p = r->n ? (double)r->count[k] / (double)r->n : 0.0;
        if (p - lo > delta || hi - p > delta)
            return 0;
    }
    return 1;
}

static int default_threads(void)
{
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > 256 ? 256 : (int)n;
}

/* Total variation between the distribution a bootstrap round started from
 * (cdf) and where its drops ended (counts): how far from stationary it is. */
static double round_distance(const double *cdf, const long *before, const long *after, int k)
{
    long n = 0;
    for (int i = 0; i < k; i++)
        n += after[i] - before[i];
    if (n == 0)
        return 1.0;
    double tv = 0.0, prev = 0.0;
    for (int i = 0; i < k; i++) {
        tv += fabs((cdf[i] - prev) - (double)(after[i] - before[i]) / (double)n);
        prev = cdf[i];
    }
    return 0.5 * tv;
}

/* Size of the next batch: the bootstrap's rounds, --ci's checks, or what is
 * left of -n; never past the cap. */
static long next_batch(const pd_sim_result *r, const pd_scene *scene, const pd_sim_options *o,
                       long want, long cap)
{
    long size = r->n < want ? want - r->n : CI_BATCH;
    if (scene->initial == PD_INITIAL_BOOTSTRAP)
        size = r->n < BOOTSTRAP_FIRST ? BOOTSTRAP_FIRST - r->n : BOOTSTRAP_ROUND;
    if (o->ci_halfwidth <= 0 && size > want - r->n)
        size = want - r->n;
    if (size > cap - r->n)
        size = cap - r->n;
    return size > BATCH_MAX ? BATCH_MAX : size;
}

/* Runs batch b, appends its records to r->trials when they are kept, and
 * tallies them (a batch cut short by cancellation marks r partial). Returns
 * the drops done, or -1 with *st set. */
static long run_recorded(batch *b, int nthreads, const pd_sim_options *o, pd_sim_result *r,
                         pd_status *st, pd_diag *diag)
{
    long done = run_batch(b, nthreads, r);
    if (done < 0) {
        *st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for a thread's work area");
        return -1;
    }
    if (o->keep_trials && done > 0) {
        pd_trial *t = realloc(r->trials, sizeof *t * (size_t)(r->n + done));
        if (!t) {
            *st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for %ld trial records", r->n + done);
            return -1;
        }
        memcpy(t + r->n, b->out, sizeof *t * (size_t)done);
        r->trials = t;
    }
    tally(r, b->out, done);
    if (done < b->last - b->first)
        r->partial = 1;
    return done;
}

static int thread_count(const pd_sim_options *o)
{
    return o->threads > 0 ? (o->threads > 256 ? 256 : o->threads) : default_threads();
}

/* With effect_halfwidth: the drops the effects ask for, given the widest
 * half-width res now at r->n drops; a half-width goes as 1 / sqrt(n), so
 * n (res / delta)^2, PD_EFFECT_ROUND_MARGIN more for the estimate's own
 * noise, and at least a batch more. 0 once res is within delta. */
static pd_status effect_want(const pd_sim_model *model, const pd_scene *scene,
                             const pd_sim_options *o, const pd_sim_result *r, long *want,
                             pd_diag *diag)
{
    pd_sensitivity *s = NULL;
    pd_status st = pd_sim_sensitivity(r, scene, model->part_size, o->effect_class_of,
                                      o->effect_nclasses, &s, diag);
    if (st != PD_OK)
        return st;
    double res = s->resolution, delta = o->effect_halfwidth;
    pd_sensitivity_free(s);
    *want = 0;
    if (res > delta) {
        double more = PD_EFFECT_ROUND_MARGIN * (double)r->n * (res * res / (delta * delta) - 1.0);
        *want = r->n + (more > CI_BATCH ? (long)fmin(more, PD_EFFECT_ROUND_MAX) : CI_BATCH);
    }
    return PD_OK;
}

static pd_status drive(const pd_sim_model *model, const pd_scene *scene, const pd_sim_options *o,
                       pd_sim_result *r, pd_diag *diag)
{
    int nthreads = thread_count(o);
    /* --ci starts from the drops that guarantee the half-width for every pose
     * at once in the worst case (p = 1/2, Bonferroni over the poses: the
     * corrected eq. 17), then adds batches while an interval is still wider. */
    long want = pd_shard_drops(o->ndrops, r->shard, r->nshards), cap = want;
    if (o->ci_halfwidth > 0 || o->effect_halfwidth > 0)
        cap = o->max_drops > want ? o->max_drops : want;
    if (o->ci_halfwidth > 0) {
        /* max_drops bounds the run whatever the half-width asks (1e-7 asks
         * for ~1e14 drops); the ndrops asked for run in any case. */
        long bound = pd_sample_size(o->ci_halfwidth, 0.05, r->nposes);
        want = bound > want ? bound : want;
        want = want < cap ? want : cap;
    }
    pd_trial *buf = malloc(sizeof *buf * BATCH_MAX);
    double *cdf = malloc(sizeof *cdf * (size_t)r->nposes);
    long *before = malloc(sizeof *before * (size_t)r->nposes);
    pd_status st = PD_OK;
    if (!buf || !cdf || !before)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop records");
    while (st == PD_OK && r->n < cap && !r->partial) {
        if (r->n >= want && o->effect_halfwidth > 0) {
            long more = 0;
            if ((st = effect_want(model, scene, o, r, &more, diag)) != PD_OK)
                break;
            want = more < cap ? more : cap;
        }
        if (r->n >= want && (o->ci_halfwidth <= 0 || ci_reached(r, o->ci_halfwidth)))
            break;
        long size = next_batch(r, scene, o, want, cap);
        const double *init = NULL;
        if (scene->initial == PD_INITIAL_BOOTSTRAP && r->n >= BOOTSTRAP_FIRST) {
            estimate_cdf(r, cdf);
            init = cdf;
        }
        batch b = {.model = model, .scene = scene, .opt = o, .init_cdf = init, .r = r,
                   .first = r->n, .last = r->n + size, .out = buf, .planned = want};
        memcpy(before, r->count, sizeof *before * (size_t)r->nposes);
        if (run_recorded(&b, nthreads, o, r, &st, diag) < 0)
            break;
        if (init) {
            r->bootstrap_rounds++;
            r->stationarity = round_distance(init, before, r->count, r->nposes);
        }
    }
    free(buf);
    free(cdf);
    free(before);
    return st;
}

/* --initial stationary: first_drops drops from uniform orientations and
 * pose_drops resting on each pose, interleaved from the first drop
 * (pd_stationary_start), so that a run stopped early has drops of every phase and
 * can still give pi. */
static pd_status drive_stationary(const pd_sim_model *model, const pd_scene *scene,
                                  const pd_sim_options *o, pd_sim_result *r, pd_diag *diag)
{
    int k = r->nposes, states = r->chain_class_of ? r->chain_states : k;
    size_t K = (size_t)k;
    pd_trial *buf = malloc(sizeof *buf * BATCH_MAX);
    /* Row i: the cumulative distribution of a point mass on pose i, so the
     * bootstrap's own release (drop.c) starts the drop resting on pose i. */
    double *point = malloc(sizeof *point * K * K);
    /* Each state's poses, in pose order (a pose is its own state without
     * classes). */
    int *first = calloc((size_t)states + 1, sizeof *first), *poses = malloc(sizeof *poses * K);
    pd_status st = PD_OK;
    if (!buf || !point || !first || !poses)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop records");
    for (size_t i = 0; point && i < K; i++)
        for (size_t j = 0; j < K; j++)
            point[i * K + j] = j >= i ? 1.0 : 0.0;
    if (st == PD_OK) {
        for (int j = 0; j < k; j++)
            first[(r->chain_class_of ? r->chain_class_of[j] : j) + 1]++;
        for (int c = 0; c < states; c++)
            first[c + 1] += first[c];
        int *at = calloc((size_t)states, sizeof *at);
        if (!at)
            st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop records");
        for (int j = 0; at && j < k; j++) {
            int c = r->chain_class_of ? r->chain_class_of[j] : j;
            poses[first[c] + at[c]++] = j;
        }
        free(at);
    }
    int nthreads = thread_count(o);
    long want = pd_shard_drops(o->ndrops, r->shard, r->nshards);
    while (st == PD_OK && r->n < want && !r->partial) {
        long size = want - r->n > BATCH_MAX ? BATCH_MAX : want - r->n;
        batch b = {.model = model, .scene = scene, .opt = o, .pose_cdfs = point,
                   .pose_drops = r->pose_drops, .nposes = states, .state_first = first,
                   .state_poses = poses, .r = r, .first = r->n, .last = r->n + size,
                   .out = buf, .planned = want};
        if (run_recorded(&b, nthreads, o, r, &st, diag) < 0)
            break;
    }
    free(buf);
    free(point);
    free(first);
    free(poses);
    return st;
}

/* p and its intervals become pi of the estimated chain and its resampled
 * intervals, when the counts define the chain; otherwise they stay count / n
 * and Wilson's (closed_classes 0 says which). The chain's states are the
 * poses, or their classes (chain_class_of), each class's share then split
 * equally among its poses, which the part's symmetry makes equally likely. */
static pd_status finish_stationary(pd_sim_result *r, pd_diag *diag)
{
    const int *class_of = r->chain_class_of;
    int K = class_of ? r->chain_states : r->nposes;
    /* One more than needed: a run of no pose asks for no bytes. */
    double *buf = malloc(sizeof *buf * (3 * (size_t)K + 1));
    int *size = calloc((size_t)K + 1, sizeof *size);
    if (!buf || !size) {
        free(buf);
        free(size);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the pose chain");
    }
    pd_markov_counts c = {K, r->first_count, r->transitions};
    pd_markov_summary s = {buf, buf + K, buf + 2 * K, 0, 0.0};
    pd_status st = pd_markov_estimate(&c, NULL, K, r->seed, &s);
    if (st == PD_OK && s.nclosed > 0) {
        for (int j = 0; j < r->nposes; j++)
            size[class_of ? class_of[j] : j]++;
        for (int j = 0; j < r->nposes; j++) {
            int cl = class_of ? class_of[j] : j;
            r->p[j] = s.p[cl] / size[cl];
            r->ci_lo[j] = s.lo[cl] / size[cl];
            r->ci_hi[j] = s.hi[cl] / size[cl];
        }
    }
    free(buf);
    free(size);
    if (st != PD_OK)
        return pd_fail(diag, st, "the long-run distribution of the pose chain: %s",
                       pd_status_str(st));
    r->closed_classes = s.nclosed;
    r->stationary_shift = s.shift;
    return PD_OK;
}

/* Whether r has the arrays its counts promise: per pose counts (and, with
 * finished, probabilities and intervals), the chain's counts both or
 * neither. A result the library made always has; a hand-made one is
 * checked before its arrays are indexed. */
static int result_arrays(const pd_sim_result *r, int finished)
{
    return r->nposes >= 0 && (r->nposes == 0 || r->count) &&
           (!finished || r->nposes == 0 || (r->p && r->ci_lo && r->ci_hi)) &&
           !r->first_count == !r->transitions;
}

pd_status pd_sim_result_finish(pd_sim_result *r, pd_diag *diag)
{
    if (!r)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_finish: NULL argument");
    if (!result_arrays(r, 1))
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_finish: the result has not the "
                       "arrays of its %d poses", r->nposes);
    for (int i = 0; i < r->nposes; i++) {
        r->p[i] = r->n ? (double)r->count[i] / (double)r->n : 0.0;
        pd_wilson(r->count[i], r->n, Z95, &r->ci_lo[i], &r->ci_hi[i]);
    }
    /* A shard's chain would be estimated from a fraction of its rows' drops;
     * only the sum of the shards defines the run's. */
    if (r->transitions && r->nshards == 0)
        return finish_stationary(r, diag);
    return PD_OK;
}

/* The stationary estimator's split of the drops, refused when it cannot
 * give every state (pose, or class) its minimum or --ci asks for a stopping
 * rule. */
static pd_status check_stationary(const pd_sim_options *o, int k, pd_diag *diag)
{
    if (o->ci_halfwidth > 0)
        return pd_fail(diag, PD_ERR_USAGE, "initial stationary splits a fixed number of drops "
                       "over the poses in advance; it does not go with a confidence half-width "
                       "(give the number of drops)");
    long need = (long)(k + 1) * PD_STATIONARY_MIN_POSE_DROPS;
    if (o->ndrops < need)
        return pd_fail(diag, PD_ERR_USAGE, "initial stationary: %ld drops are too few for %d "
                       "stable %s: each needs %d drops started resting on it and the "
                       "uniform start as many, at least %ld drops in all", o->ndrops, k,
                       o->stationary_by_class ? "classes of poses" : "poses",
                       PD_STATIONARY_MIN_POSE_DROPS, need);
    return PD_OK;
}

/* The identity of a run: the part and pose table the drops map onto, and
 * every setting that changes an outcome (not threads, trials, the shard, a
 * cancel flag or a progress callback), so that a shard of another run is
 * refused by pd_sim_result_add however alike its counts look. */
static uint64_t run_fingerprint(const pd_static_result *poses, const pd_scene *sc,
                                const pd_sim_options *o)
{
    pd_hash s;
    pd_hash_init(&s, 0x72756e); /* "run" */
    pd_hash_u64(&s, poses->part_fingerprint);
    pd_hash_ints(&s, &poses->nposes, 1);
    for (int i = 0; i < poses->nposes; i++)
        pd_hash_ints(&s, &poses->poses[i].facet, 1);
    double reals[] = {sc->height, sc->belt_speed, sc->mu, sc->restitution, sc->vibration,
                      sc->gravity, sc->contact_time, sc->tumble, o->dt, o->ci_halfwidth,
                      o->time_limit};
    pd_hash_doubles(&s, reals, (long)(sizeof reals / sizeof reals[0]));
    int ints[] = {(int)sc->law, (int)sc->initial, (int)o->engine, o->max_collisions};
    pd_hash_ints(&s, ints, (long)(sizeof ints / sizeof ints[0]));
    for (int i = 0; i < PD_NPARAMS; i++) {
        const pd_dist *r = &sc->range[i];
        double ends[] = {r->lo, r->hi};
        int kind[] = {(int)r->kind, r->auto_multiple};
        pd_hash_doubles(&s, ends, 2);
        pd_hash_ints(&s, kind, 2);
    }
    pd_hash_u64(&s, (uint64_t)o->ndrops);
    if (o->effect_halfwidth > 0) /* runs before it existed keep their identity */
        pd_hash_doubles(&s, &o->effect_halfwidth, 1);
    if (o->stationary_by_class && sc->initial == PD_INITIAL_STATIONARY)
        pd_hash_ints(&s, &o->stationary_by_class, 1);
    pd_hash_u64(&s, (uint64_t)o->max_drops);
    pd_hash_u64(&s, o->seed);
    return s.h;
}

static pd_status result_new(const pd_static_result *poses, const pd_scene *scene,
                            const pd_sim_options *o, pd_sim_result **result, pd_diag *diag)
{
    pd_scene scene_default;
    pd_sim_options options_default;
    if (!scene) {
        pd_scene_default(&scene_default);
        scene = &scene_default;
    }
    if (!o) {
        pd_sim_options_default(&options_default);
        o = &options_default;
    }
    if (!poses || !result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_new: NULL %s",
                       poses ? "result" : "static_result");
    int k = poses->nposes;
    if (k < 1 || !poses->poses || o->ndrops < 0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_new: %d poses, %ld drops: expected at "
                       "least one pose and no negative count", k, o->ndrops);
    int stationary = scene->initial == PD_INITIAL_STATIONARY;
    pd_sim_result *r = calloc(1, sizeof *r);
    if (r) {
        r->nposes = k;
        r->count = calloc((size_t)k, sizeof *r->count);
        r->p = calloc((size_t)k, sizeof *r->p);
        r->ci_lo = calloc((size_t)k, sizeof *r->ci_lo);
        r->ci_hi = calloc((size_t)k, sizeof *r->ci_hi);
        r->seed = o->seed;
        r->run_fingerprint = run_fingerprint(poses, scene, o);
        r->first_failed = -1;
        r->time_limit = o->time_limit;
        if (stationary) {
            r->first_count = calloc((size_t)k, sizeof *r->first_count);
            r->transitions = calloc((size_t)k * (size_t)k, sizeof *r->transitions);
            r->pose_drops = o->ndrops / (k + 1);
            r->first_drops = o->ndrops - k * r->pose_drops;
            r->chain_states = k;
        }
    }
    if (!r || !r->count || !r->p || !r->ci_lo || !r->ci_hi ||
        (stationary && (!r->first_count || !r->transitions))) {
        pd_sim_result_free(r);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the results");
    }
    *result = r;
    return PD_OK;
}

pd_status pd_sim_result_new(const pd_static_result *poses, const pd_scene *scene,
                            const pd_sim_options *o, pd_sim_result **result, pd_diag *diag)
{
    /* A sum of shards: the chain of classes needs the part, and pd_sim_run. */
    if (o && o->stationary_by_class && scene && scene->initial == PD_INITIAL_STATIONARY)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_new: option stationary_by_class is "
                       "for whole runs (pd_sim_run), not sums of shards");
    return result_new(poses, scene, o, result, diag);
}

/* The chain of classes of symmetric poses in place of the poses' (r made
 * for a stationary run, no drop run yet). */
static pd_status chain_by_class(const pd_part *part, const pd_static_result *poses,
                                const pd_sim_options *o, pd_sim_result *r, pd_diag *diag)
{
    int k = r->nposes, nc = 0;
    int *class_of = malloc(sizeof *class_of * (size_t)k);
    if (!class_of)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the pose classes");
    pd_status st = pd_pose_classes(part, poses, class_of, &nc, diag);
    if (st != PD_OK) {
        free(class_of);
        return st;
    }
    free(r->first_count);
    free(r->transitions);
    r->first_count = calloc((size_t)nc, sizeof *r->first_count);
    r->transitions = calloc((size_t)nc * (size_t)nc, sizeof *r->transitions);
    r->chain_class_of = class_of;
    r->chain_states = nc;
    r->pose_drops = o->ndrops / (nc + 1);
    r->first_drops = o->ndrops - nc * r->pose_drops;
    if (!r->first_count || !r->transitions)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory for the pose chain");
    return PD_OK;
}

pd_status pd_sim_result_add(pd_sim_result *sum, const pd_sim_result *s, pd_diag *diag)
{
    if (!sum || !s)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_add: NULL %s", sum ? "shard" : "sum");
    if (!result_arrays(sum, 1) || !result_arrays(s, 0))
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_add: the %s has not the arrays of "
                       "its %d poses", result_arrays(sum, 1) ? "shard" : "sum",
                       result_arrays(sum, 1) ? s->nposes : sum->nposes);
    if (s->nposes != sum->nposes || !s->transitions != !sum->transitions || s->seed != sum->seed ||
        s->first_drops != sum->first_drops || s->pose_drops != sum->pose_drops ||
        s->run_fingerprint != sum->run_fingerprint)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_add: the shard is not of this run "
                       "(%d poses, seed %llu; the run: %d poses, seed %llu; or another part, "
                       "scene or drop count)", s->nposes, (unsigned long long)s->seed,
                       sum->nposes, (unsigned long long)sum->seed);
    /* Every drop of the run in one shard only: the shards of one split,
     * each once. */
    int split = s->nshards > 0 ? s->nshards : 1, which = s->nshards > 0 ? s->shard : 0;
    if (s == sum || (sum->added_nshards && split != sum->added_nshards) || which < 0 ||
        which >= split || (sum->added && sum->added[which]))
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_add: %s", s == sum
                       ? "the sum added to itself"
                       : sum->added_nshards && split != sum->added_nshards
                           ? "a shard of another split than the shards added (its drops would "
                             "count twice)"
                           : "this shard was added already (its drops would count twice)");
    if (!sum->added) {
        if (!(sum->added = calloc((size_t)split, 1)))
            return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
        sum->added_nshards = split;
    }
    sum->added[which] = 1;
    size_t k = (size_t)sum->nposes;
    sum->n += s->n;
    sum->unsettled += s->unsettled;
    sum->time_limited += s->time_limited;
    sum->collision_limited += s->collision_limited;
    sum->failed += s->failed;
    if (s->first_failed >= 0 && (sum->first_failed < 0 || s->first_failed < sum->first_failed)) {
        sum->first_failed = s->first_failed;
        sum->failed_stage = s->failed_stage;
        sum->failed_status = s->failed_status;
    }
    sum->time_limit = fmax(sum->time_limit, s->time_limit);
    sum->energy_gain += s->energy_gain;
    sum->fallbacks += s->fallbacks;
    sum->collisions += s->collisions;
    sum->partial |= s->partial;
    for (size_t i = 0; i < k; i++)
        sum->count[i] += s->count[i];
    for (size_t i = 0; sum->transitions && i < k; i++)
        sum->first_count[i] += s->first_count[i];
    for (size_t i = 0; sum->transitions && i < k * k; i++)
        sum->transitions[i] += s->transitions[i];
    return PD_OK;
}

/* Every field of the options, so that a program's mistake is a clear status
 * rather than a run that ends every drop unsettled (or never ends). The
 * command calls it on what its options set, so it accepts nothing that this
 * refuses. */
pd_status pd_sim_options_check(const pd_sim_options *o, pd_diag *diag)
{
    if (!o)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_options_check: NULL options");
    const struct {
        const char *name;
        double value;
    } reals[] = {{"dt", o->dt}, {"ci_halfwidth", o->ci_halfwidth}, {"time_limit", o->time_limit}};
    for (size_t i = 0; i < sizeof reals / sizeof reals[0]; i++)
        if (!isfinite(reals[i].value))
            return pd_fail(diag, PD_ERR_NONFINITE, "option %s is %g", reals[i].name,
                           reals[i].value);
    if ((unsigned)o->engine > (unsigned)PD_ENGINE_BULLET)
        return pd_fail(diag, PD_ERR_USAGE, "option engine is %d: expected PD_ENGINE_IMPULSE, "
                       "PD_ENGINE_ODE or PD_ENGINE_BULLET", (int)o->engine);
    if (o->dt < 0 || o->dt > PD_SIM_DT_MAX)
        return pd_fail(diag, PD_ERR_USAGE, "option dt is %g s: expected 0 (automatic, "
                       "from the scene) or a step above 0 and at most %g s", o->dt, PD_SIM_DT_MAX);
    if (o->ndrops < 0)
        return pd_fail(diag, PD_ERR_USAGE, "option ndrops is %ld: expected 0 or more", o->ndrops);
    if (o->trace_drop < 0)
        return pd_fail(diag, PD_ERR_USAGE, "option trace_drop is %ld: expected 0 or more",
                       o->trace_drop);
    if (o->threads < 0)
        return pd_fail(diag, PD_ERR_USAGE, "option threads is %d: expected 0 (all cores) or "
                       "more", o->threads);
    if (o->ci_halfwidth < 0 || o->ci_halfwidth >= 0.5)
        return pd_fail(diag, PD_ERR_USAGE, "option ci_halfwidth is %g: expected 0 (a fixed "
                       "number of drops) or a half-width above 0 and below 0.5", o->ci_halfwidth);
    if (o->max_drops < 0)
        return pd_fail(diag, PD_ERR_USAGE, "option max_drops is %ld: expected 0 or more",
                       o->max_drops);
    if (!(o->time_limit >= 0))
        return pd_fail(diag, PD_ERR_USAGE, "option time_limit is %g s: expected a positive "
                       "time or PD_TIME_LIMIT_AUTO (0)", o->time_limit);
    if (o->max_collisions < 1)
        return pd_fail(diag, PD_ERR_USAGE, "option max_collisions is %d: expected 1 or more",
                       o->max_collisions);
    if (o->keep_trials != 0 && o->keep_trials != 1)
        return pd_fail(diag, PD_ERR_USAGE, "option keep_trials is %d: expected 0 or 1",
                       o->keep_trials);
    if (o->stationary_by_class != 0 && o->stationary_by_class != 1)
        return pd_fail(diag, PD_ERR_USAGE, "option stationary_by_class is %d: expected 0 or 1",
                       o->stationary_by_class);
    if (o->stationary_by_class && o->nshards > 0)
        return pd_fail(diag, PD_ERR_USAGE, "option stationary_by_class with nshards: the chain "
                       "of classes is for whole runs");
    if (o->nshards < 0 || (o->nshards > 0 && (o->shard < 0 || o->shard >= o->nshards)))
        return pd_fail(diag, PD_ERR_USAGE, "options nshards %d, shard %d: expected nshards 0 "
                       "(the whole run), or shard from 0 to nshards - 1", o->nshards, o->shard);
    if (o->nshards > 0 && o->ci_halfwidth > 0)
        return pd_fail(diag, PD_ERR_USAGE, "option nshards with ci_halfwidth: a run split into "
                       "shards needs a fixed number of drops");
    if (!isfinite(o->effect_halfwidth))
        return pd_fail(diag, PD_ERR_NONFINITE, "option effect_halfwidth is %g",
                       o->effect_halfwidth);
    if (o->effect_halfwidth < 0 || o->effect_halfwidth >= 0.5)
        return pd_fail(diag, PD_ERR_USAGE, "option effect_halfwidth is %g: expected 0 (a fixed "
                       "number of drops) or a half-width above 0 and below 0.5",
                       o->effect_halfwidth);
    if (o->effect_halfwidth > 0 && (o->nshards > 0 || !o->keep_trials))
        return pd_fail(diag, PD_ERR_USAGE, "option effect_halfwidth needs keep_trials and no "
                       "shards: the effects come from the drops' records, and their number "
                       "from the effects");
    return PD_OK;
}

pd_status pd_sim_run(const pd_part *part, const pd_static_result *poses, const pd_scene *scene,
                     const pd_sim_options *options, pd_sim_result **result, pd_diag *diag)
{
    pd_scene sc;
    pd_sim_options o;
    if (scene)
        sc = *scene;
    else
        pd_scene_default(&sc);
    if (options)
        o = *options;
    else
        pd_sim_options_default(&o);
    pd_status st = pd_static_result_check(part, poses, "pd_sim_run", diag);
    if (st != PD_OK)
        return st;
    if (!result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_run: NULL result");
    st = pd_scene_check(&sc, diag);
    if (st == PD_OK)
        st = pd_sim_options_check(&o, diag);
    if (st != PD_OK)
        return st;
    if (!pd_engine_available(o.engine))
        return pd_fail(diag, PD_ERR_UNAVAILABLE, "pd_sim_run: the Bullet engine is not in this "
                       "program: link libposedrop-bullet (pkg-config posedrop-bullet) and call "
                       "pd_bullet_register() first");
    if (poses->nposes < 1)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_run: the static result has no stable pose");
    if (o.nshards > 0 && sc.initial == PD_INITIAL_BOOTSTRAP)
        return pd_fail(diag, PD_ERR_USAGE, "a run split into shards needs a fixed number of "
                       "drops, each independent of the others' outcomes: not a confidence "
                       "half-width, nor the bootstrap start, which draws from the outcomes so far");
    if (o.effect_halfwidth > 0 && !pd_scene_ranged(&sc))
        return pd_fail(diag, PD_ERR_USAGE, "option effect_halfwidth: no scene parameter varies, "
                       "so there is no effect to resolve (give a range)");
    if (o.effect_halfwidth > 0 && sc.initial != PD_INITIAL_UNIFORM)
        return pd_fail(diag, PD_ERR_USAGE, "option effect_halfwidth goes with the uniform start "
                       "only");
    int stationary = sc.initial == PD_INITIAL_STATIONARY;
    int by_class = stationary && o.stationary_by_class;
    pd_sim_result *r = NULL;
    st = result_new(poses, &sc, &o, &r, diag);
    if (st == PD_OK && by_class)
        st = chain_by_class(part, poses, &o, r, diag);
    if (st != PD_OK) {
        pd_sim_result_free(r);
        return st;
    }
    if (stationary && check_stationary(&o, r->chain_states, diag) != PD_OK) {
        pd_sim_result_free(r);
        return PD_ERR_USAGE;
    }
    pd_sim_model *model = NULL;
    st = pd_sim_model_build(part, poses, &sc, &o, &model, diag);
    if (st != PD_OK) {
        pd_sim_result_free(r);
        return st;
    }
    if (st == PD_OK) {
        r->time_limit = model->time_limit;
        r->nshards = o.nshards;
        r->shard = o.nshards ? o.shard : 0;
        st = stationary ? drive_stationary(model, &sc, &o, r, diag) : drive(model, &sc, &o, r, diag);
    }
    pd_sim_model_free(model);
    if (st != PD_OK) {
        pd_sim_result_free(r);
        return st;
    }
    if ((st = pd_sim_result_finish(r, diag)) != PD_OK) {
        pd_sim_result_free(r);
        return st;
    }
    *result = r;
    return PD_OK;
}
