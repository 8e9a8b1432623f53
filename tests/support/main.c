/* main.c: the test runner. Runs every suite, or those named on the command
 * line, and ends with the line "N passed, N failed"; the exit code is non-zero
 * when any check failed. Measured figures (pd_note) only with
 * PD_TEST_VERBOSE=1. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "suites.h"

int pd_checks_passed, pd_checks_failed;

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

int main(int argc, char **argv)
{
    int nsuites = (int)(sizeof suites / sizeof suites[0]);
    int matched = 0;
    for (int i = 0; i < nsuites; i++) {
        int run = argc < 2;
        for (int a = 1; a < argc; a++)
            if (strcmp(argv[a], suites[i].name) == 0)
                run = 1;
        if (!run)
            continue;
        matched++;
        int p0 = pd_checks_passed, f0 = pd_checks_failed;
        suites[i].run();
        printf("suite %-8s %d passed, %d failed\n", suites[i].name,
               pd_checks_passed - p0, pd_checks_failed - f0);
        fflush(stdout);
    }
    if (matched == 0) {
        fprintf(stderr, "no suite matches; suites are:");
        for (int i = 0; i < nsuites; i++)
            fprintf(stderr, " %s", suites[i].name);
        fprintf(stderr, "\n");
        printf("0 passed, 1 failed\n");
        return 1;
    }
    printf("%d passed, %d failed\n", pd_checks_passed, pd_checks_failed);
    return pd_checks_failed != 0;
}
