/* vbuf.c: the growing text buffer (see vbuf.h). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "viz/vbuf.h"

void vbuf_init(vbuf *b)
{
    memset(b, 0, sizeof *b);
}

void vbuf_free(vbuf *b)
{
    free(b->data);
    vbuf_init(b);
}

static int reserve(vbuf *b, size_t extra)
{
    if (b->failed)
        return 0;
    if (b->len + extra + 1 <= b->cap)
        return 1;
    size_t cap = b->cap ? b->cap : 4096;
    while (cap < b->len + extra + 1) {
        if (cap > ((size_t)-1) / 2) {
            b->failed = 1;
            return 0;
        }
        cap *= 2;
    }
    char *d = realloc(b->data, cap);
    if (!d) {
        b->failed = 1;
        return 0;
    }
    b->data = d;
    b->cap = cap;
    return 1;
}

void vbuf_putn(vbuf *b, const char *s, size_t n)
{
    if (!reserve(b, n))
        return;
    memcpy(b->data + b->len, s, n);
    b->len += n;
    b->data[b->len] = '\0';
}

void vbuf_put(vbuf *b, const char *s)
{
    vbuf_putn(b, s, strlen(s));
}

void vbuf_printf(vbuf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    if (n < 0) {
        b->failed = 1;
        return;
    }
    if (!reserve(b, (size_t)n))
        return;
    va_start(ap, fmt);
    vsnprintf(b->data + b->len, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

void vbuf_escape(vbuf *b, const char *s)
{
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        switch (c) {
        case '&': vbuf_put(b, "&amp;"); break;
        case '<': vbuf_put(b, "&lt;"); break;
        case '>': vbuf_put(b, "&gt;"); break;
        case '"': vbuf_put(b, "&quot;"); break;
        case '\'': vbuf_put(b, "&#39;"); break;
        default:
            if (c < 0x20 && c != '\t' && c != '\n')
                c = '?';
            vbuf_putn(b, (const char *)&c, 1);
        }
    }
}

void vbuf_num(vbuf *b, double x)
{
    /* A non-finite coordinate would make the file invalid; none is expected
     * (every input is checked finite), so this only keeps the XML valid. */
    double r = isfinite(x) ? round(x * 100.0) / 100.0 : 0.0;
    if (r == 0.0)
        r = 0.0; /* no "-0" */
    char tmp[48];
    int n = snprintf(tmp, sizeof tmp, "%.2f", r);
    /* Trailing zeros carry nothing: "12.50" -> "12.5", "3.00" -> "3". */
    while (n > 0 && tmp[n - 1] == '0')
        n--;
    if (n > 0 && tmp[n - 1] == '.')
        n--;
    vbuf_putn(b, tmp, (size_t)n);
}
