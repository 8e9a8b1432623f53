/* vbuf.h: a growing text buffer that the SVG and HTML writers print into.
 *
 * Out of memory is remembered rather than returned by every call, so the
 * drawing code reads straight; the caller checks vbuf.failed once at the end. */
#ifndef PD_VIZ_VBUF_H
#define PD_VIZ_VBUF_H

#include <stddef.h>
#include "base/fail.h"

typedef struct vbuf {
    char *data;    /* NUL-terminated when len > 0 */
    size_t len, cap;
    int failed;    /* 1 once an allocation failed: the text is then incomplete */
} vbuf;

void vbuf_init(vbuf *b);
void vbuf_free(vbuf *b);
void vbuf_put(vbuf *b, const char *s);
void vbuf_putn(vbuf *b, const char *s, size_t n);
void vbuf_printf(vbuf *b, const char *fmt, ...) PD_PRINTF(2, 3);
/* s with &, <, >, " and ' written as character references, so any text
 * (a file name, a command line) is safe in XML content and attribute values;
 * control characters other than tab and newline, which XML 1.0 forbids, are
 * written as '?'. */
void vbuf_escape(vbuf *b, const char *s);
/* A coordinate in user units: two decimals are 1/100 px, far below what any
 * renderer shows, and keep the files small. -0.00 is written as 0. */
void vbuf_num(vbuf *b, double x);

#endif
