/* text.h (private): a bounded line and token cursor over text that is NOT
 * NUL-terminated (a file read whole, or a caller's buffer), and the number
 * parsing that the mesh readers and scene files share. Nothing here hands
 * the input to a C string function: every scan is bounded by the range's
 * end, and numbers are copied into a small terminated buffer before strtod
 * sees them. */
#ifndef PD_TEXT_H
#define PD_TEXT_H

#include <stddef.h>
#include "posedrop/types.h"
#include "base/fail.h"
#include "base/number.h" /* pd_parse_double and its outcomes */

/* --- text cursor ---------------------------------------------------------- */

/* Walks a text one line at a time and a line one token at a time, so that
 * messages can name the line and a record's extra tokens can be ignored. */
typedef struct pd_text {
    const char *name;    /* for messages */
    const char *p;       /* start of the next raw line */
    const char *end;     /* end of the input: never read at or past it */
    const char *tok;     /* next unread byte of the current line */
    const char *eol;     /* end of the current line, comment and '\' cut off */
    long long line;      /* 1-based number of the current raw line */
    char comment;        /* character starting a comment to end of line, or 0 */
    int join;            /* a trailing backslash joins the next line (OBJ) */
    int cont;            /* the current raw line ends with such a backslash */
    pd_cancel_flag *cancel; /* may be NULL: read every few thousand lines; once
                               found set, the input ends there (cancelled = 1) */
    unsigned lines;
    int cancelled;
} pd_text;

void pd_text_init(pd_text *t, const void *data, size_t size, const char *name, char comment,
                  int join);
/* Moves to the next line holding a token; 0 at end of input. */
int pd_text_next_line(pd_text *t);
/* Next token of the current line (s, n); 0 when the line has no more. */
int pd_text_token(pd_text *t, const char **s, size_t *n);
/* Next token, moving on to later lines as needed; 0 at end of input. */
int pd_text_token_any(pd_text *t, const char **s, size_t *n);
/* Bytes from the cursor to the end of the input: bounds what counts can be. */
size_t pd_text_left(const pd_text *t);
/* Case-insensitive comparison of a token with a keyword. */
int pd_text_is(const char *s, size_t n, const char *word);
/* A token quoted for a message ('abc', cut short and with control bytes
 * replaced), or "end of line" when s is NULL. Returns buf. */
const char *pd_text_show(char *buf, size_t size, const char *s, size_t n);
/* pd_fail with "name:line: " in front of the message. */
pd_status pd_text_fail(const pd_text *t, pd_diag *diag, pd_status status, const char *fmt, ...)
    PD_PRINTF(4, 5);

/* --- numbers ---------------------------------------------------------------- */

/* A whole token as a decimal integer, saturated at +-1e18 (callers compare it
 * with far smaller limits). 0 if the token is not an integer. */
int pd_parse_int(const char *s, size_t n, long long *out);
/* Reads the next token of the line as a coordinate scaled by scale, with the
 * message for a missing, malformed, non-finite or underflowing one
 * ("expected what"). */
pd_status pd_text_coord(pd_text *t, pd_diag *diag, const char *what, double scale, double *out);

#endif
