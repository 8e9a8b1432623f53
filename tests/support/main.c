/* main.c: the test runner. Runs every suite, or those named on the command
 * line, and ends with the line "N passed, N failed"; the exit code is non-zero
 * when any check failed. Measured figures (pd_note) only with
 * PD_TEST_VERBOSE=1.
 *
 *   test_posedrop [-j N] [--full] [suite...]
 *
 * -j N runs up to N suites at once, each in a process of its own; a suite's
 * output is held until those before it have printed, so the output reads as
 * a run one suite at a time (the default, -j 1, runs them in this process).
 * A suite that crashes or ends with a non-zero status (a sanitizer's report)
 * counts one failure. --full selects the long variants of the statistical
 * tests (pd_test_full), which make check-full runs. */
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "suites.h"

int pd_checks_passed, pd_checks_failed;
static int full_mode;

int pd_test_full(void) { return full_mode; }

void pd_check_report(int ok, const char *file, int line, const char *what)
{
    if (ok) {
        pd_checks_passed++;
        return;
    }
    pd_checks_failed++;
    printf("FAIL %s:%d: %s\n", file, line, what);
}

void pd_check_report_num(int ok, const char *file, int line, const char *expr,
                         double actual, double expected, double tol, const char *source)
{
    if (ok) {
        pd_checks_passed++;
        return;
    }
    pd_checks_failed++;
    printf("FAIL %s:%d: %s\n     actual   %.17g\n     expected %.17g\n     tolerance %.3g (%s)\n",
           file, line, expr, actual, expected, tol, source);
}

void pd_note(const char *fmt, ...)
{
    static int verbose = -1;
    if (verbose < 0) {
        const char *v = getenv("PD_TEST_VERBOSE");
        verbose = v && strcmp(v, "1") == 0;
    }
    if (!verbose)
        return;
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
}

static const struct {
    const char *name;
    void (*run)(void);
} suites[] = {
#define PD_SUITE(name) {#name, suite_##name},
    PD_SUITES
#undef PD_SUITE
};
enum { NSUITES = sizeof suites / sizeof suites[0] };

/* A suite run in a child process: its stdout and stderr held in temporary
 * files, its counts sent back through a pipe. */
typedef struct {
    int suite;
    pid_t pid;
    FILE *out, *err;
    int counts; /* read end of the pipe */
    int passed, failed, done;
} job;

static void suite_line(int s, int passed, int failed)
{
    printf("suite %-8s %d passed, %d failed\n", suites[s].name, passed, failed);
    fflush(stdout);
}

static int start(job *j)
{
    int fd[2];
    j->out = tmpfile();
    j->err = tmpfile();
    if (!j->out || !j->err || pipe(fd) != 0)
        return 0;
    fflush(stdout);
    fflush(stderr);
    j->pid = fork();
    if (j->pid < 0)
        return 0;
    if (j->pid == 0) {
        close(fd[0]);
        dup2(fileno(j->out), STDOUT_FILENO);
        dup2(fileno(j->err), STDERR_FILENO);
        pd_checks_passed = pd_checks_failed = 0;
        suites[j->suite].run();
        fflush(stdout);
        int c[2] = {pd_checks_passed, pd_checks_failed};
        ssize_t w = write(fd[1], c, sizeof c);
        close(fd[1]);
        /* exit, not _exit: the leak checker of a sanitizer build runs here. */
        exit(w == (ssize_t)sizeof c ? 0 : 1);
    }
    close(fd[1]);
    j->counts = fd[0];
    return 1;
}

static void copy(FILE *from, FILE *to)
{
    char buf[4096];
    size_t n;
    rewind(from);
    while ((n = fread(buf, 1, sizeof buf, from)) > 0)
        fwrite(buf, 1, n, to);
    fclose(from);
    fflush(to);
}

/* Collects a finished child: its counts, or one failure if it did not end
 * cleanly. */
static void finish(job *j, int status)
{
    int c[2] = {0, 0};
    ssize_t r;
    do
        r = read(j->counts, c, sizeof c);
    while (r < 0 && errno == EINTR);
    close(j->counts);
    j->passed = c[0];
    j->failed = c[1];
    if (r != (ssize_t)sizeof c || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        j->failed++;
        fprintf(j->out, "FAIL suite %s: %s %d\n", suites[j->suite].name,
                WIFSIGNALED(status) ? "killed by signal" : "exited with status",
                WIFSIGNALED(status) ? WTERMSIG(status) : WEXITSTATUS(status));
        fflush(j->out); /* a later fork must not inherit it buffered */
    }
    j->done = 1;
}

static void run_forked(const int *chosen, int n, int jobs)
{
    job *js = calloc((size_t)n, sizeof *js);
    if (!js) {
        pd_checks_failed++;
        return;
    }
    int next = 0, running = 0, printed = 0;
    while (printed < n) {
        while (running < jobs && next < n) {
            js[next].suite = chosen[next];
            if (!start(&js[next])) {
                printf("FAIL could not start suite %s\n", suites[chosen[next]].name);
                js[next].failed = 1;
                js[next].done = 1;
                js[next].pid = 0;
            } else {
                running++;
            }
            next++;
        }
        if (running > 0) {
            int status;
            pid_t pid = wait(&status);
            if (pid < 0 && errno == EINTR)
                continue;
            if (pid < 0) { /* no child left to wait for: count the rest failed */
                for (int i = 0; i < next; i++)
                    if (!js[i].done)
                        finish(&js[i], 1 << 8);
                running = 0;
            }
            for (int i = 0; i < next; i++)
                if (pid > 0 && js[i].pid == pid && !js[i].done) {
                    finish(&js[i], status);
                    running--;
                }
        }
        while (printed < n && js[printed].done) {
            job *j = &js[printed];
            if (j->out)
                copy(j->out, stdout);
            if (j->err)
                copy(j->err, stderr);
            suite_line(j->suite, j->passed, j->failed);
            pd_checks_passed += j->passed;
            pd_checks_failed += j->failed;
            printed++;
        }
    }
    free(js);
}

int main(int argc, char **argv)
{
    int jobs = 1, chosen[NSUITES], nchosen = 0, named = 0;
    char *sel = calloc(NSUITES, 1);
    for (int a = 1; a < argc; a++) {
        const char *arg = argv[a];
        if (strcmp(arg, "--full") == 0) {
            full_mode = 1;
        } else if (strncmp(arg, "-j", 2) == 0) {
            const char *v = arg[2] ? arg + 2 : (a + 1 < argc ? argv[++a] : "");
            char *end;
            long j = strtol(v, &end, 10);
            if (*v == '\0' || *end != '\0' || j < 1 || j > 256) {
                fprintf(stderr, "test_posedrop: -j wants a number of jobs from 1 to 256, not '%s'\n", v);
                printf("0 passed, 1 failed\n");
                return 1;
            }
            jobs = (int)j;
        } else {
            int found = 0;
            for (int i = 0; i < NSUITES; i++)
                if (strcmp(arg, suites[i].name) == 0)
                    sel[i] = found = 1;
            if (!found) {
                fprintf(stderr, "no suite is called '%s'; suites are:", arg);
                for (int i = 0; i < NSUITES; i++)
                    fprintf(stderr, " %s", suites[i].name);
                fprintf(stderr, "\n");
                printf("0 passed, 1 failed\n");
                return 1;
            }
            named = 1;
        }
    }
    for (int i = 0; i < NSUITES; i++)
        if (!named || sel[i])
            chosen[nchosen++] = i;
    free(sel);
    if (jobs > 1 && nchosen > 1) {
        run_forked(chosen, nchosen, jobs);
    } else {
        for (int k = 0; k < nchosen; k++) {
            int p0 = pd_checks_passed, f0 = pd_checks_failed;
            suites[chosen[k]].run();
            suite_line(chosen[k], pd_checks_passed - p0, pd_checks_failed - f0);
        }
    }
    printf("%d passed, %d failed\n", pd_checks_passed, pd_checks_failed);
    return pd_checks_failed != 0;
}
