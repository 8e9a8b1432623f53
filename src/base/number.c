/* number.c: reading numbers the user types (see number.h). */
#include <errno.h>
#include <limits.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/number.h"

int pd_parse_double(const char *s, size_t n, double *out)
{
    /* strtod needs a terminated string; no genuine number is this long. */
    char buf[128];
    if (n == 0 || n >= sizeof buf)
        return PD_NUM_BAD;
    memcpy(buf, s, n);
    buf[n] = '\0';
    /* strtod would skip leading blanks; a token has none, and a typed value
     * has had both ends trimmed, so a blank here is part of a bad token. */
    if (buf[0] == ' ' || (buf[0] >= '\t' && buf[0] <= '\r'))
        return PD_NUM_BAD;
    char *stop;
    errno = 0;
    double v = strtod(buf, &stop);
    if (stop != buf + n)
        return PD_NUM_BAD;
    if (!isfinite(v))
        return PD_NUM_NONFINITE;
    /* Underflow: strtod gives 0 or a subnormal with ERANGE. Refused rather
     * than read as 0, so that "1e-400" means the same for every setting. */
    if ((errno == ERANGE || v != 0.0) && fabs(v) < DBL_MIN)
        return PD_NUM_TINY;
    *out = v;
    return PD_NUM_OK;
}

/* A decimal integer token, exactly; PD_NUM_RANGE beyond 64 bits. */
static int parse_whole(const char *s, size_t n, long long *out)
{
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '+' || s[i] == '-'))
        neg = s[i++] == '-';
    if (i == n)
        return PD_NUM_BAD;
    /* Accumulated as a negative number, whose range holds INT64_MIN. */
    long long v = 0;
    int over = 0;
    for (; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return PD_NUM_BAD;
        int d = s[i] - '0';
        if (v < (LLONG_MIN + d) / 10)
            over = 1;
        else
            v = v * 10 - d;
    }
    if (over || (!neg && v == LLONG_MIN))
        return PD_NUM_RANGE;
    *out = neg ? v : -v;
    return PD_NUM_OK;
}

static int is_blank(char c)
{
    return c == ' ' || (c >= '\t' && c <= '\r');
}

int pd_num_read(const pd_num_rule *rule, const char *text, double *real, long long *whole)
{
    const char *s = text, *e = text + strlen(text);
    while (s < e && is_blank(*s))
        s++;
    while (e > s && is_blank(e[-1]))
        e--;
    size_t n = (size_t)(e - s);
    if (rule->whole) {
        long long v;
        int rc = parse_whole(s, n, &v);
        if (rc != PD_NUM_OK)
            return rc;
        if (v < rule->ilo || v > rule->ihi)
            return PD_NUM_RANGE;
        *whole = v;
        return PD_NUM_OK;
    }
    double v;
    int rc = pd_parse_double(s, n, &v);
    if (rc != PD_NUM_OK)
        return rc;
    if (v < rule->lo || v > rule->hi || (rule->lo_open && v == rule->lo) ||
        (rule->hi_open && v == rule->hi))
        return PD_NUM_RANGE;
    *real = v;
    return PD_NUM_OK;
}

const char *pd_num_message(char *buf, size_t size, const pd_num_rule *rule, const char *text,
                           int outcome)
{
    char lo[32], hi[32], range[96];
    if (rule->whole) {
        snprintf(lo, sizeof lo, "%lld", rule->ilo);
        snprintf(hi, sizeof hi, "%lld", rule->ihi);
    } else {
        snprintf(lo, sizeof lo, "%g", rule->lo);
        snprintf(hi, sizeof hi, "%g", rule->hi);
    }
    if (!rule->lo_open && !rule->hi_open)
        snprintf(range, sizeof range, "from %s to %s", lo, hi);
    else
        snprintf(range, sizeof range, "%s %s and %s %s", rule->lo_open ? "above" : "at least", lo,
                 rule->hi_open ? "below" : "at most", hi);
    const char *why = "out of range";
    switch (outcome) {
    case PD_NUM_BAD:
        why = rule->whole ? "not a whole number" : "not a number";
        break;
    case PD_NUM_NONFINITE:
        why = "not a finite number";
        break;
    case PD_NUM_TINY:
        why = "non-zero but below the smallest normal double, 2.2e-308";
        break;
    default:
        break;
    }
    /* Long values are cut: the message is one line. */
    snprintf(buf, size, "expected %s %s, got '%.40s%s' (%s)", rule->what, range, text,
             strlen(text) > 40 ? "..." : "", why);
    return buf;
}

const char *pd_num_format(char *buf, size_t size, double v, double scale)
{
    if (!buf || size == 0)
        return buf;
    /* Fewest significant digits first: "9.81" rather than the
     * 9.8100000000000005 of %.17g, which reads back the same. */
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, v / scale);
        if (strtod(buf, NULL) * scale == v)
            return buf;
    }
    snprintf(buf, size, "%.17g", v / scale);
    return buf;
}
