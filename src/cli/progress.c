/* progress.c: a progress line on stderr for long runs, only when stderr is a
 * terminal (a log file or a pipe gets nothing), redrawn at most
 * REDRAWS_PER_S times a second so that drawing costs nothing next to the
 * drops. */
#include <stdio.h>
#include <time.h>
#include <unistd.h>
#include "cli/cli.h"

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
    if (!isatty(STDERR_FILENO))
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
