/* text.c: the bounded text cursor and number parsing (see text.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/text.h"

/* --- text cursor ---------------------------------------------------------- */

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

void pd_text_init(pd_text *t, const void *data, size_t size, const char *name, char comment,
                  int join)
{
    memset(t, 0, sizeof *t);
    t->name = name;
    t->p = data;
    t->end = t->p ? t->p + size : NULL;
    /* Editors on some systems start UTF-8 text with a byte-order mark; it
     * would otherwise glue itself to the first keyword. */
    if (size >= 3 && memcmp(t->p, "\xEF\xBB\xBF", 3) == 0)
        t->p += 3;
    t->comment = comment;
    t->join = join;
}

/* Makes the next raw line current; 0 at end of input. */
static int load_raw(pd_text *t)
{
    if (t->p == NULL || t->p >= t->end)
        return 0;
    const char *start = t->p;
    const char *nl = memchr(start, '\n', (size_t)(t->end - start));
    const char *stop = nl ? nl : t->end;
    t->p = nl ? nl + 1 : t->end;
    t->line++;
    if (t->comment) {
        const char *c = memchr(start, t->comment, (size_t)(stop - start));
        if (c)
            stop = c;
    }
    t->cont = 0;
    if (t->join) {
        const char *e = stop;
        while (e > start && is_space(e[-1]))
            e--;
        if (e > start && e[-1] == '\\') {
            stop = e - 1;
            t->cont = 1;
        }
    }
    t->tok = start;
    t->eol = stop;
    return 1;
}

/* Skips blanks, following joined lines; 1 if a token is next. */
static int skip_space(pd_text *t)
{
    for (;;) {
        while (t->tok < t->eol && is_space(*t->tok))
            t->tok++;
        if (t->tok < t->eol)
            return 1;
        if (!t->cont || !load_raw(t))
            return 0;
    }
}

int pd_text_next_line(pd_text *t)
{
    /* A cancelled read ends its input: the reader stops at its next line,
     * and its caller, seeing cancelled, reports the cancel rather than
     * what the reader made of the short input. */
    if (t->cancel && ++t->lines % 4096 == 0 &&
        atomic_load_explicit(t->cancel, memory_order_relaxed))
        t->cancelled = 1;
    if (t->cancelled)
        return 0;
    /* The rest of a joined line belongs to the record being left. */
    while (t->cont && load_raw(t)) {
    }
    while (load_raw(t))
        if (skip_space(t))
            return 1;
    return 0;
}

int pd_text_token(pd_text *t, const char **s, size_t *n)
{
    if (!skip_space(t))
        return 0;
    *s = t->tok;
    while (t->tok < t->eol && !is_space(*t->tok))
        t->tok++;
    *n = (size_t)(t->tok - *s);
    return 1;
}

int pd_text_token_any(pd_text *t, const char **s, size_t *n)
{
    for (;;) {
        if (pd_text_token(t, s, n))
            return 1;
        if (!pd_text_next_line(t))
            return 0;
    }
}

size_t pd_text_left(const pd_text *t)
{
    const char *from = t->tok ? t->tok : t->p;
    return from ? (size_t)(t->end - from) : 0;
}

static char lower(char c)
{
    return (c >= 'A' && c <= 'Z') ? (char)(c - 'A' + 'a') : c;
}

int pd_text_is(const char *s, size_t n, const char *word)
{
    size_t i = 0;
    for (; i < n; i++)
        if (word[i] == '\0' || lower(s[i]) != lower(word[i]))
            return 0;
    return word[i] == '\0';
}

const char *pd_text_show(char *buf, size_t size, const char *s, size_t n)
{
    if (s == NULL) {
        snprintf(buf, size, "end of line");
        return buf;
    }
    /* Long enough to recognise the token, short enough for a one-line message. */
    enum { SHOWN = 24 };
    char tmp[SHOWN + 1];
    size_t k = n < SHOWN ? n : SHOWN;
    for (size_t i = 0; i < k; i++) {
        unsigned char c = (unsigned char)s[i];
        tmp[i] = (c >= 0x20 && c < 0x7f) ? (char)c : '?';
    }
    tmp[k] = '\0';
    snprintf(buf, size, "'%s%s'", tmp, n > k ? "..." : "");
    return buf;
}

pd_status pd_text_fail(const pd_text *t, pd_diag *diag, pd_status status, const char *fmt, ...)
{
    if (!diag)
        return status;
    char text[PD_DIAG_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    return pd_fail(diag, status, "%s:%lld: %s", t->name, t->line, text);
}

/* --- numbers ---------------------------------------------------------------- */

int pd_parse_int(const char *s, size_t n, long long *out)
{
    /* Saturating keeps "99999999999999999999" an honest too-large count
     * instead of an overflowed one. */
    const long long cap = 1000000000000000000LL;
    size_t i = 0;
    int neg = 0;
    if (i < n && (s[i] == '+' || s[i] == '-'))
        neg = s[i++] == '-';
    if (i == n)
        return 0;
    long long v = 0;
    for (; i < n; i++) {
        if (s[i] < '0' || s[i] > '9')
            return 0;
        v = v <= (cap - 9) / 10 ? v * 10 + (s[i] - '0') : cap;
    }
    *out = neg ? -v : v;
    return 1;
}

pd_status pd_text_coord(pd_text *t, pd_diag *diag, const char *what, double scale, double *out)
{
    const char *s;
    size_t n;
    char shown[48];
    if (!pd_text_token(t, &s, &n))
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected %s, found end of line", what);
    double v;
    int rc = pd_parse_double(s, n, &v);
    if (rc == PD_NUM_BAD)
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected %s, found %s", what,
                            pd_text_show(shown, sizeof shown, s, n));
    v *= scale;
    if (rc == PD_NUM_NONFINITE || !isfinite(v))
        return pd_text_fail(t, diag, PD_ERR_NONFINITE, "expected %s (a finite number), found %s",
                            what, pd_text_show(shown, sizeof shown, s, n));
    if (rc == PD_NUM_TINY)
        return pd_text_fail(t, diag, PD_ERR_RANGE, "%s %s is non-zero but below the smallest "
                            "normal double, 2.2e-308", what, pd_text_show(shown, sizeof shown, s, n));
    *out = v;
    return PD_OK;
}
