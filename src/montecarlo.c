/* montecarlo.c: running many drops on all cores, deterministically.
 *
 * Work is cut into batches of drop indices. Within a batch, threads take
 * indices from a shared counter and write each outcome at its index; the
 * batch is tallied in index order after all threads finish. Each drop's
 * randomness comes from its own stream (seed, index), so neither the thread
 * count nor the scheduling can change a byte of the result. What depends on
 * earlier outcomes (the bootstrap's initial distribution, the --ci stopping
 * rule) is decided between batches, on tallies of whole batches only. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "diag.h"
#include "drop.h"
#include "stats.h"

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
    memset(o, 0, sizeof *o);
    o->engine = PD_ENGINE_IMPULSE;
    o->dt = 0.0;
    o->ndrops = 2000;
    o->seed = 1;
    o->threads = 0;
    o->ci_halfwidth = 0.0;
    o->max_drops = 10000000;
    o->time_limit = 20.0;
    o->max_collisions = 100000;
    o->keep_trials = 0;
    o->cancel = NULL;
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
    free(r);
}

typedef struct batch {
    const pd_sim_model *model;
    const pd_scene *scene;
    const pd_sim_options *opt;
    const double *init_cdf;
    long first, last;       /* drop indices [first, last) */
    pd_trial *out;          /* out[i - first] */
    atomic_long next;
    atomic_long energy_gain;
    atomic_long fallbacks;
    atomic_int failed;      /* a thread could not get its work area */
} batch;

static int cancelled(const pd_sim_options *o) { return o->cancel && *o->cancel; }

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
        if (i >= b->last || cancelled(b->opt))
            break;
        pd_drop_run(b->model, w, b->scene, b->opt, i, b->init_cdf, &b->out[i - b->first], &gain,
                    &fallbacks);
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
    atomic_store(&b->energy_gain, 0);
    atomic_store(&b->fallbacks, 0);
    atomic_store(&b->failed, 0);
    /* Zeroed first, padding included, so records compare byte for byte. */
    memset(b->out, 0, sizeof *b->out * (size_t)(b->last - b->first));
    for (long i = 0; i < b->last - b->first; i++)
        b->out[i].end = (pd_drop_end)-1; /* not run */
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
    while (b->first + done < b->last && (int)b->out[done].end >= 0)
        done++;
    return atomic_load(&b->failed) && done < b->last - b->first ? -1 : done;
}

static void tally(pd_sim_result *r, const pd_trial *t, long n)
{
    for (long i = 0; i < n; i++) {
        r->collisions += t[i].collisions;
        if (t[i].end == PD_END_SETTLED && t[i].pose >= 0)
            r->count[t[i].pose]++;
        else
            r->unsettled++;
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

static pd_status drive(const pd_sim_model *model, const pd_scene *scene, const pd_sim_options *o,
                       pd_sim_result *r, pd_diag *diag)
{
    int nthreads = o->threads > 0 ? (o->threads > 256 ? 256 : o->threads) : default_threads();
    /* --ci starts from the drops that guarantee the half-width for every pose
     * at once in the worst case (p = 1/2, Bonferroni over the poses: the
     * corrected eq. 17), then adds batches while an interval is still wider. */
    long want = o->ndrops;
    if (o->ci_halfwidth > 0) {
        long bound = pd_sample_size(o->ci_halfwidth, 0.05, r->nposes);
        want = bound > want ? bound : want;
    }
    long cap = o->ci_halfwidth > 0 ? (o->max_drops > want ? o->max_drops : want) : want;
    pd_trial *buf = malloc(sizeof *buf * BATCH_MAX);
    double *cdf = malloc(sizeof *cdf * (size_t)r->nposes);
    long *before = malloc(sizeof *before * (size_t)r->nposes);
    pd_status st = PD_OK;
    if (!buf || !cdf || !before)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop records");
    while (st == PD_OK && r->n < cap && !r->partial) {
        if (r->n >= want && (o->ci_halfwidth <= 0 || ci_reached(r, o->ci_halfwidth)))
            break;
        long size = next_batch(r, scene, o, want, cap);
        const double *init = NULL;
        if (scene->initial == PD_INITIAL_BOOTSTRAP && r->n >= BOOTSTRAP_FIRST) {
            estimate_cdf(r, cdf);
            init = cdf;
        }
        batch b = {.model = model, .scene = scene, .opt = o, .init_cdf = init, .first = r->n,
                   .last = r->n + size, .out = buf};
        memcpy(before, r->count, sizeof *before * (size_t)r->nposes);
        long done = run_batch(&b, nthreads, r);
        if (done < 0) {
            st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for a thread's work area");
            break;
        }
        if (o->keep_trials && done > 0) {
            pd_trial *t = realloc(r->trials, sizeof *t * (size_t)(r->n + done));
            if (!t) {
                st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for %ld trial records", r->n + done);
                break;
            }
            memcpy(t + r->n, buf, sizeof *t * (size_t)done);
            r->trials = t;
        }
        tally(r, buf, done);
        if (init) {
            r->bootstrap_rounds++;
            r->stationarity = round_distance(init, before, r->count, r->nposes);
        }
        if (done < size)
            r->partial = 1;
    }
    free(buf);
    free(cdf);
    free(before);
    return st;
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
    if (!part || !poses || !result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_run: NULL argument");
    if (o.ndrops < 0 || o.max_drops < 0 || !(o.ci_halfwidth >= 0) || !(o.time_limit > 0) ||
        o.max_collisions < 1 || !(o.dt >= 0 && o.dt < 1) ||
        (unsigned)o.engine > (unsigned)PD_ENGINE_BULLET)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_run: invalid options");
    if (poses->nposes < 1)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_run: the part has no stable pose");
    pd_sim_model *model = NULL;
    pd_status st = pd_sim_model_build(part, poses, &sc, &o, &model, diag);
    if (st != PD_OK)
        return st;
    pd_sim_result *r = calloc(1, sizeof *r);
    int k = poses->nposes;
    if (r) {
        r->nposes = k;
        r->count = calloc((size_t)k, sizeof *r->count);
        r->p = calloc((size_t)k, sizeof *r->p);
        r->ci_lo = calloc((size_t)k, sizeof *r->ci_lo);
        r->ci_hi = calloc((size_t)k, sizeof *r->ci_hi);
    }
    if (!r || !r->count || !r->p || !r->ci_lo || !r->ci_hi)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the results");
    else
        st = drive(model, &sc, &o, r, diag);
    pd_sim_model_free(model);
    if (st != PD_OK) {
        pd_sim_result_free(r);
        return st;
    }
    for (int i = 0; i < k; i++) {
        r->p[i] = r->n ? (double)r->count[i] / (double)r->n : 0.0;
        pd_wilson(r->count[i], r->n, Z95, &r->ci_lo[i], &r->ci_hi[i]);
    }
    *result = r;
    return PD_OK;
}
