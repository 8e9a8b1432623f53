/* progress.c: a progress line on stderr for long runs, only when stderr is a
 * terminal (a log file or a pipe gets nothing), redrawn at most
 * REDRAWS_PER_S times a second so that drawing costs nothing next to the
 * drops. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>
#include "cli/cli.h"

/* The static estimate is quiet for this long: most parts take a fraction
 * of a second, and a line that flashes by says nothing. */
#define STATIC_QUIET_S 2.0

static int forced;

void progress_force(void)
{
    forced = 1;
}

static int wanted(void)
{
    return forced || isatty(STDERR_FILENO);
}

#define REDRAWS_PER_S 4.0

static struct {
    struct timespec start;
    double last;  /* s after start of the last redraw */
    int drawn;
} line;

static double now_since(const struct timespec *t0)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)(t.tv_sec - t0->tv_sec) + 1e-9 * (double)(t.tv_nsec - t0->tv_nsec);
}

static void format_time(double s, char *buf, size_t size)
{
    long t = (long)(s + 0.5);
    if (t >= 3600)
        snprintf(buf, size, "%ldh%02ldm", t / 3600, t / 60 % 60);
    else if (t >= 60)
        snprintf(buf, size, "%ldm%02lds", t / 60, t % 60);
    else
        snprintf(buf, size, "%lds", t);
}

static void draw(void *user, long done, long total)
{
    (void)user;
    double t = now_since(&line.start);
    /* The last drop is always drawn, so the line ends on the true count. */
    if (line.drawn && t - line.last < 1.0 / REDRAWS_PER_S && done < total)
        return;
    line.last = t;
    line.drawn = 1;
    double rate = t > 0 ? (double)done / t : 0.0;
    char left[32] = "?";
    if (rate > 0)
        format_time((double)(total > done ? total - done : 0) / rate, left, sizeof left);
    /* \033[K clears what a longer previous line left behind. */
    fprintf(stderr, "\r%s: %ld of %ld drops, %.0f drops/s, %s left\033[K", prog, done, total, rate,
            left);
    fflush(stderr);
}

void progress_attach(pd_sim_options *options)
{
    if (!wanted())
        return;
    clock_gettime(CLOCK_MONOTONIC, &line.start);
    line.drawn = 0;
    options->progress = draw;
    options->progress_user = NULL;
}

void progress_clear(void)
{
    if (line.drawn)
        fprintf(stderr, "\r\033[K");
    line.drawn = 0;
}

static struct {
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t wake;
    int running, done, drawn;
    struct timespec start;
    _Atomic(const char *) stage;
} st = {.lock = PTHREAD_MUTEX_INITIALIZER, .wake = PTHREAD_COND_INITIALIZER};

static void on_stage(void *user, const char *name)
{
    (void)user;
    atomic_store(&st.stage, name);
}

void static_progress_stage(const char *name)
{
    atomic_store(&st.stage, name);
}

/* Redraws the line REDRAWS_PER_S times a second once the estimate has run
 * STATIC_QUIET_S; on a terminal in place, elsewhere (--progress into a file)
 * one line per stage. */
static void *watch(void *arg)
{
    (void)arg;
    const char *shown = NULL;
    pthread_mutex_lock(&st.lock);
    while (!st.done) {
        struct timespec until;
        clock_gettime(CLOCK_REALTIME, &until);
        long ns = until.tv_nsec + (long)(1e9 / REDRAWS_PER_S);
        until.tv_sec += ns / 1000000000L;
        until.tv_nsec = ns % 1000000000L;
        pthread_cond_timedwait(&st.wake, &st.lock, &until);
        double t = now_since(&st.start);
        const char *stage = atomic_load(&st.stage);
        if (st.done || t < STATIC_QUIET_S || !stage)
            continue;
        if (isatty(STDERR_FILENO)) {
            fprintf(stderr, "\r%s: static estimate: %s, %.0f s\033[K", prog, stage, t);
            st.drawn = 1;
        } else if (stage != shown) {
            fprintf(stderr, "%s: static estimate: %s, %.0f s\n", prog, stage, t);
        }
        shown = stage;
        fflush(stderr);
    }
    pthread_mutex_unlock(&st.lock);
    return NULL;
}

void static_progress_begin(pd_part_options *options)
{
    if (!wanted() || st.running)
        return;
    clock_gettime(CLOCK_MONOTONIC, &st.start);
    st.done = st.drawn = 0;
    atomic_store(&st.stage, "reading");
    options->stage = on_stage;
    options->stage_user = NULL;
    st.running = pthread_create(&st.thread, NULL, watch, NULL) == 0;
}

void static_progress_end(void)
{
    if (!st.running)
        return;
    pthread_mutex_lock(&st.lock);
    st.done = 1;
    pthread_cond_signal(&st.wake);
    pthread_mutex_unlock(&st.lock);
    pthread_join(st.thread, NULL);
    st.running = 0;
    if (st.drawn)
        fprintf(stderr, "\r\033[K");
    st.drawn = 0;
}
