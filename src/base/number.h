/* number.h (private): the one reading of a number that a user types, shared
 * by the command line, scene files and the mesh readers' coordinates, so that
 * "1e-400", " 5" or "inf" mean the same wherever they are given, and one
 * message form says what was expected, in which range, and what was wrong.
 *
 * Depends on the C library only: the command line links this file directly. */
#ifndef PD_NUMBER_H
#define PD_NUMBER_H

#include <stddef.h>

/* Outcomes of reading one number. */
enum {
    PD_NUM_OK,
    PD_NUM_BAD,       /* not a number (or, for a whole number, not an integer) */
    PD_NUM_NONFINITE, /* nan, inf, or beyond the largest double like 1e999 */
    PD_NUM_TINY,      /* non-zero but below the smallest normal double (1e-400):
                         it would silently read as 0 or lose its digits */
    PD_NUM_RANGE      /* a number outside the rule's range */
};

/* What a setting accepts: a real in [lo, hi] (either end open), or a whole
 * number in [ilo, ihi] read exactly as a 64-bit integer (seeds go to
 * 2^63 - 1, beyond a double's exact integers). */
typedef struct {
    const char *what; /* "a friction coefficient", for messages */
    int whole;        /* 1: an integer in [ilo, ihi]; 0: a real in lo..hi */
    double lo, hi;
    int lo_open, hi_open;
    long long ilo, ihi;
} pd_num_rule;

/* One token of exactly n bytes (no blanks) as a finite double: PD_NUM_OK,
 * PD_NUM_BAD, PD_NUM_NONFINITE or PD_NUM_TINY. The mesh readers' coordinates. */
int pd_parse_double(const char *s, size_t n, double *out);

/* A typed value (a command-line argument or a scene file's value): blanks at
 * either end are ignored, the rest must be one number obeying the rule. Sets
 * *real (rule->whole == 0) or *whole (rule->whole == 1) only on PD_NUM_OK. */
int pd_num_read(const pd_num_rule *rule, const char *text, double *real, long long *whole);

/* The message for a refused value, one form everywhere:
 * "expected WHAT from LO to HI, got 'TEXT' (WHY)". Returns buf. */
const char *pd_num_message(char *buf, size_t size, const pd_num_rule *rule, const char *text,
                           int outcome);

/* v as the shortest text (%.Ng, N from 1 to 17) that reads back to it
 * when its number is multiplied by scale, the way a scene stores a value
 * typed in degrees: "9.81", not "9.8100000000000005". Returns buf. */
const char *pd_num_format(char *buf, size_t size, double v, double scale);

#endif
