/* check.h: the counting checks of the test runner.
 *
 * Every check counts as passed or failed; a failure prints file:line, the
 * expression, both values with %.17g and where its tolerance comes from.
 * A check never stops the run, so one run shows every failure. */
#ifndef PD_TEST_CHECK_H
#define PD_TEST_CHECK_H

#include <math.h>
#include <stdio.h>

extern int pd_checks_passed;
extern int pd_checks_failed;

void pd_check_report(int ok, const char *file, int line, const char *what);
void pd_check_report_num(int ok, const char *file, int line, const char *expr,
                         double actual, double expected, double tol, const char *source);

/* A measured figure worth reading (errors reached, counts of cases): printed
 * only with PD_TEST_VERBOSE=1 in the environment, so that a plain run shows
 * failures and totals alone. */
void pd_note(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* 1 under make check-full (the runner's --full): the statistical tests that
 * allow it run their long variants, more trials at the same level. */
int pd_test_full(void);

/* A boolean property. */
#define CHECK(cond) pd_check_report(!!(cond), __FILE__, __LINE__, #cond)

/* Integers (counts, indices, statuses) must be equal. */
#define CHECK_INT(actual, expected)                                                        \
    do {                                                                                   \
        long long a_ = (long long)(actual), e_ = (long long)(expected);                    \
        pd_check_report_num(a_ == e_, __FILE__, __LINE__, #actual " == " #expected,        \
                            (double)a_, (double)e_, 0.0, "exact");                         \
    } while (0)

/* |actual - expected| <= tol, absolute; source says why tol is what it is
 * ("round-off", "closed form", "3 sigma of n = 1e5 trials", ...). NaN fails. */
#define CHECK_NEAR(actual, expected, tol, source)                                          \
    do {                                                                                   \
        double a_ = (actual), e_ = (expected), t_ = (tol);                                 \
        pd_check_report_num(fabs(a_ - e_) <= t_, __FILE__, __LINE__, #actual " ~ " #expected, \
                            a_, e_, t_, source);                                           \
    } while (0)

/* |actual - expected| <= rel * |expected|, relative. NaN fails. */
#define CHECK_REL(actual, expected, rel, source)                                           \
    do {                                                                                   \
        double a_ = (actual), e_ = (expected), t_ = (rel);                                 \
        pd_check_report_num(fabs(a_ - e_) <= t_ * fabs(e_), __FILE__, __LINE__,            \
                            #actual " ~rel " #expected, a_, e_, t_, source);               \
    } while (0)

/* A call returning pd_status must return the expected one. */
#define CHECK_STATUS(call, expected) CHECK_INT((int)(call), (int)(expected))

#endif
