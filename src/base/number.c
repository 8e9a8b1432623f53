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

/* The common case of pd_parse_double without strtod: [+-]digits[.digits]
 * [(e|E)[+-]digits] with at most 19 significant digits w and a power of
 * ten 10^e, |e| <= 27, both exact in x87's 64-bit extended mantissa (5^27 <
 * 2^64). One extended product or quotient is then w * 10^e rounded once,
 * within half a unit of its 64th bit; rounding that to a double gives the
 * correctly rounded double unless the true value and the extended one may
 * lie on two sides of a midpoint between doubles, which the 11 bits
 * rounded off show: within one unit of 10000000000 (binary) the answer is
 * left to strtod. That is round-to-nearest; under a directed rounding mode
 * that a caller may have set (strtod follows it too) the two roundings go
 * the same way and compose exactly, doubles being extended values. 1 with
 * *out set, 0 when strtod must decide (other forms, more digits, a larger
 * exponent, or a near-midpoint). Text that strtod
 * reads differently (hexadecimal, inf, nan, blanks, a bare point) never
 * takes this path. A large mesh file holds millions of such coordinates,
 * most of them printed with 17 digits. */
static int parse_fast(const char *s, size_t n, double *out)
{
#if LDBL_MANT_DIG == 64 && (defined(__x86_64__) || defined(__i386__))
    size_t i = 0;
    int neg = 0, digits = 0, sig = 0, scale = 0;
    uint64_t w = 0;
    if (i < n && (s[i] == '+' || s[i] == '-'))
        neg = s[i++] == '-';
    for (; i < n && s[i] >= '0' && s[i] <= '9'; i++, digits++) {
        if (w == 0 && s[i] == '0')
            continue; /* a leading zero: not significant */
        if (++sig > 19)
            return 0;
        w = 10 * w + (uint64_t)(s[i] - '0');
    }
    if (i < n && s[i] == '.')
        for (i++; i < n && s[i] >= '0' && s[i] <= '9'; i++, digits++) {
            scale--;
            if (w == 0 && s[i] == '0')
                continue;
            if (++sig > 19)
                return 0;
            w = 10 * w + (uint64_t)(s[i] - '0');
        }
    if (digits == 0)
        return 0;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        int eneg = 0, ex = 0, edigits = 0;
        i++;
        if (i < n && (s[i] == '+' || s[i] == '-'))
            eneg = s[i++] == '-';
        for (; i < n && s[i] >= '0' && s[i] <= '9'; i++)
            if (++edigits > 4)
                return 0;
            else
                ex = 10 * ex + (s[i] - '0');
        if (edigits == 0)
            return 0;
        scale += eneg ? -ex : ex;
    }
    if (i != n)
        return 0;
    if (w == 0) {
        *out = neg ? -0.0 : 0.0;
        return 1;
    }
    if (scale < -27 || scale > 27)
        return 0;
    /* Exact: 10^27 = 5^27 2^27, and 5^27 < 2^63. */
    static const long double ten[28] = {1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,
                                        1e7L,  1e8L,  1e9L,  1e10L, 1e11L, 1e12L, 1e13L,
                                        1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L, 1e20L,
                                        1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
    /* Signed before it is rounded, so that a directed rounding goes the
     * way the mode says for a negative number too. */
    long double sw = neg ? -(long double)w : (long double)w;
    long double x = scale < 0 ? sw / ten[-scale] : sw * ten[scale];
    uint64_t mant;
    memcpy(&mant, &x, sizeof mant); /* the explicit 64-bit significand */
    unsigned low = (unsigned)(mant & 0x7ff);
    if (low >= 0x3ff && low <= 0x401)
        return 0;
    *out = (double)x;
    return 1;
#else
    (void)s;
    (void)n;
    (void)out;
    return 0;
#endif
}

int pd_parse_double(const char *s, size_t n, double *out)
{
    if (parse_fast(s, n, out))
        return PD_NUM_OK;
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
