/* test_number.c: one reading of numbers everywhere (base/number.c): the
 * outcomes of odd texts, exact 64-bit whole numbers, the one message form,
 * and the same refusal of an underflowing number in a mesh coordinate. */
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <fenv.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/number.h"
#include "check.h"
#include "posedrop/mesh.h"
#include "suites.h"

/* The shortest round-trip text: the fewest digits that read back, checked
 * by reading back (an invariance) on values whose short form is known and
 * on values that need all 17 digits. */
static void test_format(void)
{
    char buf[32];
    CHECK(strcmp(pd_num_format(buf, sizeof buf, 9.81, 1.0), "9.81") == 0);
    CHECK(strcmp(pd_num_format(buf, sizeof buf, 0.3, 1.0), "0.3") == 0);
    CHECK(strcmp(pd_num_format(buf, sizeof buf, 5e-4, 1.0), "0.0005") == 0);
    /* Degrees stored as radians: the text typed, not (v / scale)'s digits. */
    const double deg = 3.14159265358979323846 / 180.0;
    CHECK(strcmp(pd_num_format(buf, sizeof buf, 1.5 * deg, deg), "1.5") == 0);
    const double hard[] = {0.1 + 0.2, 1.0 / 3.0, 2.0 / 3.0 * deg, DBL_MIN, DBL_MAX, -7.25e-300};
    for (int i = 0; i < 6; i++) {
        double scale = i == 2 ? deg : 1.0;
        pd_num_format(buf, sizeof buf, hard[i], scale);
        CHECK(strtod(buf, NULL) * scale == hard[i]);
    }
    CHECK(strcmp(pd_num_format(buf, sizeof buf, 0.1 + 0.2, 1.0), "0.30000000000000004") == 0);
}

/* The reading of one token as strtod reads it (the reference): the whole
 * token consumed, finite, not below the smallest normal. */
static int by_strtod(const char *text, double *v)
{
    char *stop;
    errno = 0;
    double x = strtod(text, &stop);
    if (text[0] == '\0' || text[0] == ' ' || *stop != '\0')
        return PD_NUM_BAD;
    if (!isfinite(x))
        return PD_NUM_NONFINITE;
    if ((errno == ERANGE || x != 0.0) && fabs(x) < DBL_MIN)
        return PD_NUM_TINY;
    *v = x;
    return PD_NUM_OK;
}

static uint64_t prng = 0x9e3779b97f4a7c15ULL;
static uint64_t next64(void)
{
    prng ^= prng << 13;
    prng ^= prng >> 7;
    prng ^= prng << 17;
    return prng;
}

static int below(int n)
{
    return (int)(next64() % (uint64_t)n);
}

/* pd_parse_double's outcome and bits against strtod's on text; 1 when
 * they differ. */
static int differs(const char *text)
{
    double a = 0.0, b = 0.0;
    int ra = pd_parse_double(text, strlen(text), &a), rb = by_strtod(text, &b);
    return ra != rb || (ra == PD_NUM_OK && memcmp(&a, &b, sizeof a) != 0);
}

/* A random decimal: sign or none, leading zeros, 1 to 21 significant
 * digits (19 is the most the fast reading takes), a point anywhere or
 * none, an exponent of either letter, sign and up to 4 digits or none. */
static void random_decimal(char *buf)
{
    int n = 0, sig = 1 + below(21), point = below(sig + 3) - 1;
    const char *signs[3] = {"", "-", "+"};
    n += sprintf(buf + n, "%s", signs[below(3)]);
    for (int z = below(3); z > 0; z--)
        buf[n++] = '0';
    for (int i = 0; i < sig; i++) {
        if (i == point)
            buf[n++] = '.';
        buf[n++] = (char)('0' + (i == 0 ? 1 + below(9) : below(10)));
    }
    if (point >= sig)
        buf[n++] = '.';
    if (below(4) > 0)
        n += sprintf(buf + n, "%c%s%0*d", below(2) ? 'e' : 'E', signs[below(3)], 1 + below(3),
                     below(45));
    buf[n] = '\0';
}

/* The fast reading of coordinates (number.c's parse_fast) against strtod,
 * bit for bit, on text drawn to reach its edges: 200,000 random decimals;
 * 100,000 doubles printed with 17 significant digits as the mesh files
 * hold them, in both notations; 100,000 texts of 17 to 19 digits at and next to a midpoint
 * between two doubles, where a reading that rounds twice goes wrong (the
 * midpoint printed to 17 to 19 digits, its last digit moved by -2 to 2);
 * up to 2,000 midpoints between doubles that are integers below 10^19
 * (2^53 + 2k + 1 times a power of two), each as an integer and with
 * ".0e0"; and 100,000 random strings of digits, points, signs, letters and
 * blanks, whose outcome (not a number, or its value) must be strtod's
 * too. No difference allowed: the reading is exact or it is a defect. */
static void test_parse_vs_strtod(void)
{
    char buf[96];
    int bad = 0;
    for (int i = 0; i < 200000; i++) {
        random_decimal(buf);
        bad += differs(buf);
    }
    CHECK_INT(bad, 0);
    bad = 0;
    for (int i = 0; i < 100000; i++) {
        double x = ldexp((double)(next64() >> 11) * 0x1p-53 + 0.5, below(160) - 80);
        sprintf(buf, "%.17g", below(2) ? x : -x);
        bad += differs(buf);
        sprintf(buf, "%.16e", x);
        bad += differs(buf);
    }
    CHECK_INT(bad, 0);
    bad = 0;
    for (int i = 0; i < 100000; i++) {
        double x = ldexp((double)(next64() >> 11) * 0x1p-53 + 0.5, below(120) - 60);
        long double mid = ((long double)x + (long double)nextafter(x, HUGE_VAL)) / 2.0L;
        int digits = 17 + below(3);
        sprintf(buf, "%.*Le", digits - 1, mid);
        char *e = strchr(buf, 'e');
        int last = e[-1] - '0' + below(5) - 2;
        if (last >= 0 && last <= 9)
            e[-1] = (char)('0' + last);
        bad += differs(buf);
    }
    CHECK_INT(bad, 0);
    bad = 0;
    for (int i = 0; i < 2000; i++) {
        /* (2^53 + 2k + 1) 2^(j - 1): halfway between two doubles of step 2^j. */
        int j = below(11);
        uint64_t k = next64() % (1ULL << 52);
        uint64_t v = ((1ULL << 53) + 2 * k + 1) << j >> 1;
        if (j == 0 || v >= 10000000000000000000ULL)
            continue;
        sprintf(buf, "%llu", (unsigned long long)v);
        bad += differs(buf);
        sprintf(buf, "%llu.0e0", (unsigned long long)v);
        bad += differs(buf);
    }
    CHECK_INT(bad, 0);
    bad = 0;
    const char alphabet[] = "0123456789.eE+-x ";
    for (int i = 0; i < 100000; i++) {
        int n = 1 + below(12);
        for (int k = 0; k < n; k++)
            buf[k] = alphabet[below((int)sizeof alphabet - 1)];
        buf[n] = '\0';
        bad += differs(buf);
    }
    CHECK_INT(bad, 0);
    /* The forms at the fast path's edges, each as strtod reads them. */
    const char *edges[] = {"0",     "-0",   "-0.0e5", ".5",     "5.",      "+.5e+1", "1e",
                           "1e+",   ".",    "-",      "1e27",   "1e-27",   "1e28",   "1e-28",
                           "9999999999999999999",     "18446744073709551616",   "1e0005",
                           "00000000000000000000001", "0.000000000000000000000000001"};
    for (size_t i = 0; i < sizeof edges / sizeof *edges; i++)
        CHECK(!differs(edges[i]));
}

/* Under each directed rounding mode a caller may set, strtod rounds that
 * way, and so must the fast reading (number.c: its two roundings then
 * compose exactly): 20,000 random decimals and 20,000 doubles printed with
 * 17 digits per mode, bit for bit. */
static void test_parse_directed(void)
{
    static const int modes[] = {FE_UPWARD, FE_DOWNWARD, FE_TOWARDZERO};
    char buf[96];
    for (size_t m = 0; m < sizeof modes / sizeof *modes; m++) {
        int bad = 0;
        if (fesetround(modes[m]) != 0)
            continue; /* a machine without the mode: nothing to compare */
        for (int i = 0; i < 20000; i++) {
            random_decimal(buf);
            bad += differs(buf);
            double x = ldexp((double)(next64() >> 11) * 0x1p-53 + 0.5, below(160) - 80);
            sprintf(buf, "%.17g", below(2) ? x : -x);
            bad += differs(buf);
        }
        fesetround(FE_TONEAREST);
        CHECK_INT(bad, 0);
    }
}

static int real(const pd_num_rule *r, const char *text, double *v)
{
    return pd_num_read(r, text, v, NULL);
}

void suite_number(void)
{
    test_format();
    test_parse_vs_strtod();
    test_parse_directed();
    const pd_num_rule angle = {"an angle", 0, 0.0, 90.0, 0, 0, 0, 0};
    const pd_num_rule open = {"a half-width", 0, 0.0, 0.5, 1, 1, 0, 0};
    const pd_num_rule seed = {"a seed", 1, 0, 0, 0, 0, 0, LLONG_MAX};
    double v = -1.0;
    long long n = -1;

    /* Blanks at either end are ignored alike; inside they spoil the number. */
    CHECK_INT(real(&angle, " 5", &v), PD_NUM_OK);
    CHECK(v == 5.0);
    CHECK_INT(real(&angle, "5 ", &v), PD_NUM_OK);
    CHECK_INT(real(&angle, "\t5\n", &v), PD_NUM_OK);
    CHECK_INT(real(&angle, "5 0", &v), PD_NUM_BAD);
    CHECK_INT(real(&angle, "", &v), PD_NUM_BAD);
    CHECK_INT(real(&angle, "  ", &v), PD_NUM_BAD);
    /* Underflow is refused whatever the range: 1e-400 would read as 0 and a
     * subnormal has lost digits. 0 itself and the smallest normal are fine. */
    v = -1.0;
    CHECK_INT(real(&angle, "1e-400", &v), PD_NUM_TINY);
    CHECK_INT(real(&open, "1e-400", &v), PD_NUM_TINY);
    CHECK_INT(real(&angle, "-1e-400", &v), PD_NUM_TINY);
    CHECK_INT(real(&angle, "4e-320", &v), PD_NUM_TINY);
    CHECK(v == -1.0); /* untouched on failure */
    CHECK_INT(real(&angle, "0", &v), PD_NUM_OK);
    CHECK(v == 0.0);
    CHECK_INT(real(&angle, "2.2250738585072014e-308", &v), PD_NUM_OK);
    CHECK(v == DBL_MIN);
    CHECK_INT(real(&angle, "1e999", &v), PD_NUM_NONFINITE);
    CHECK_INT(real(&angle, "nan", &v), PD_NUM_NONFINITE);
    CHECK_INT(real(&angle, "-inf", &v), PD_NUM_NONFINITE);
    CHECK_INT(real(&angle, "90.0000001", &v), PD_NUM_RANGE);
    CHECK_INT(real(&angle, "90", &v), PD_NUM_OK);
    CHECK_INT(real(&open, "0.5", &v), PD_NUM_RANGE);
    CHECK_INT(real(&open, "0", &v), PD_NUM_RANGE);

    /* Whole numbers: exact up to 2^63 - 1, beyond that out of range (not
     * saturated or wrapped), and no fractions or exponents. */
    CHECK_INT(pd_num_read(&seed, "9223372036854775807", NULL, &n), PD_NUM_OK);
    CHECK(n == LLONG_MAX);
    CHECK_INT(pd_num_read(&seed, "2000000000000000001", NULL, &n), PD_NUM_OK);
    CHECK(n == 2000000000000000001LL);
    CHECK_INT(pd_num_read(&seed, "9223372036854775808", NULL, &n), PD_NUM_RANGE);
    CHECK_INT(pd_num_read(&seed, "99999999999999999999999", NULL, &n), PD_NUM_RANGE);
    CHECK_INT(pd_num_read(&seed, "-1", NULL, &n), PD_NUM_RANGE);
    CHECK_INT(pd_num_read(&seed, " 7 ", NULL, &n), PD_NUM_OK);
    CHECK(n == 7);
    CHECK_INT(pd_num_read(&seed, "1e3", NULL, &n), PD_NUM_BAD);
    CHECK_INT(pd_num_read(&seed, "2.5", NULL, &n), PD_NUM_BAD);
    CHECK_INT(pd_num_read(&seed, "+", NULL, &n), PD_NUM_BAD);

    /* One message form, stating the range whatever went wrong. */
    char msg[256];
    pd_num_message(msg, sizeof msg, &angle, "1e308", PD_NUM_RANGE);
    CHECK(strcmp(msg, "expected an angle from 0 to 90, got '1e308' (out of range)") == 0);
    pd_num_message(msg, sizeof msg, &open, "x", PD_NUM_BAD);
    CHECK(strcmp(msg, "expected a half-width above 0 and below 0.5, got 'x' (not a number)") == 0);
    pd_num_message(msg, sizeof msg, &seed, "9223372036854775808", PD_NUM_RANGE);
    CHECK(strstr(msg, "from 0 to 9223372036854775807") != NULL);
    pd_num_message(msg, sizeof msg, &angle, "1e-400", PD_NUM_TINY);
    CHECK(strstr(msg, "from 0 to 90") != NULL && strstr(msg, "2.2e-308") != NULL);

    /* A mesh coordinate of 1e-400 is refused like any other number, with its
     * line, in both readers that read coordinates as text. */
    const char *off = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1e-400 0\n0 0 1\n"
                      "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    const char *obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1e-400\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    const char *texts[2] = {off, obj}, *where[2] = {"t.off:5:", "t.obj:4:"};
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    for (int i = 0; i < 2; i++) {
        pd_mesh *m = NULL;
        pd_diag d;
        pd_diag_init(&d);
        ro.format = i ? PD_FORMAT_OBJ : PD_FORMAT_OFF;
        CHECK_STATUS(pd_mesh_parse(texts[i], strlen(texts[i]), i ? "t.obj" : "t.off", &ro, &m, &d),
                     PD_ERR_RANGE);
        CHECK(strstr(d.message, where[i]) != NULL && strstr(d.message, "2.2e-308") != NULL);
        CHECK(m == NULL);
        pd_mesh_free(m);
    }
}
