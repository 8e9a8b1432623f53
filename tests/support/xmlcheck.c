/* xmlcheck.c: the XML well-formedness checker (see xmlcheck.h). */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "xmlcheck.h"

const char *const xml_svg11_elements[] = {"svg", "g", "title", "rect", "polygon", "path",
                                          "circle", "text", NULL};

enum { DEPTH_MAX = 256, NAME_MAX_LEN = 64, ATTR_MAX = 32 };

typedef struct {
    const char *p, *start;
    char *err;
    size_t errsize;
} cursor;

static int fail(cursor *c, const char *fmt, ...)
{
    int line = 1;
    for (const char *q = c->start; q < c->p; q++)
        line += *q == '\n';
    int n = snprintf(c->err, c->errsize, "line %d: ", line);
    va_list ap;
    va_start(ap, fmt);
    if (n >= 0 && (size_t)n < c->errsize)
        vsnprintf(c->err + n, c->errsize - (size_t)n, fmt, ap);
    va_end(ap);
    return 0;
}

static int name_start(char ch)
{
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || ch == '_' || ch == ':';
}

static int name_char(char ch)
{
    return name_start(ch) || (ch >= '0' && ch <= '9') || ch == '-' || ch == '.';
}

static int read_name(cursor *c, char *out)
{
    if (!name_start(*c->p))
        return fail(c, "expected a name, found '%c'", *c->p ? *c->p : '?');
    int n = 0;
    while (name_char(*c->p)) {
        if (n + 1 >= NAME_MAX_LEN)
            return fail(c, "name too long");
        out[n++] = *c->p++;
    }
    out[n] = '\0';
    return 1;
}

static void skip_space(cursor *c)
{
    while (*c->p == ' ' || *c->p == '\t' || *c->p == '\n' || *c->p == '\r')
        c->p++;
}

/* An entity or character reference at c->p ('&'). */
static int reference(cursor *c)
{
    static const char *const named[] = {"&amp;", "&lt;", "&gt;", "&quot;", "&apos;"};
    for (int i = 0; i < 5; i++)
        if (!strncmp(c->p, named[i], strlen(named[i]))) {
            c->p += strlen(named[i]);
            return 1;
        }
    if (c->p[1] == '#') {
        const char *q = c->p + 2;
        int hex = *q == 'x';
        q += hex;
        const char *digits = q;
        while ((*q >= '0' && *q <= '9') || (hex && ((*q >= 'a' && *q <= 'f') || (*q >= 'A' && *q <= 'F'))))
            q++;
        if (q > digits && *q == ';') {
            c->p = q + 1;
            return 1;
        }
    }
    return fail(c, "'&' that starts no reference");
}

static int is_allowed(const char *name, const char *const *allowed)
{
    if (!allowed)
        return 1;
    for (int i = 0; allowed[i]; i++)
        if (!strcmp(allowed[i], name))
            return 1;
    return 0;
}

int xml_check(const char *text, const char *const *allowed, char *err, size_t errsize)
{
    cursor c = {text, text, err, errsize};
    char stack[DEPTH_MAX][NAME_MAX_LEN];
    int depth = 0, roots = 0;
    if (errsize)
        err[0] = '\0';
    if (!strncmp(c.p, "<?xml", 5)) {
        const char *end = strstr(c.p, "?>");
        if (!end)
            return fail(&c, "unterminated XML declaration");
        c.p = end + 2;
    }
    for (;;) {
        if (depth == 0)
            skip_space(&c);
        if (*c.p == '\0')
            break;
        if (*c.p != '<') {
            if (depth == 0)
                return fail(&c, "text outside the root element");
            if (*c.p == '&') {
                if (!reference(&c))
                    return 0;
            } else if (*c.p == '>' && c.p > text + 1 && c.p[-1] == ']' && c.p[-2] == ']') {
                return fail(&c, "']]>' in text");
            } else {
                c.p++;
            }
            continue;
        }
        if (!strncmp(c.p, "<!--", 4)) {
            const char *end = strstr(c.p + 4, "-->");
            if (!end)
                return fail(&c, "unterminated comment");
            c.p = end + 3;
            continue;
        }
        if (!strncmp(c.p, "<!DOCTYPE", 9)) {
            if (depth || roots)
                return fail(&c, "DOCTYPE after the root element started");
            const char *end = strchr(c.p, '>');
            if (!end)
                return fail(&c, "unterminated DOCTYPE");
            c.p = end + 1;
            continue;
        }
        if (c.p[1] == '/') {
            char name[NAME_MAX_LEN];
            c.p += 2;
            if (!read_name(&c, name))
                return 0;
            skip_space(&c);
            if (*c.p != '>')
                return fail(&c, "expected '>' closing </%s", name);
            c.p++;
            if (depth == 0 || strcmp(stack[depth - 1], name))
                return fail(&c, "</%s> does not close <%s>", name, depth ? stack[depth - 1] : "(none)");
            depth--;
            continue;
        }
        c.p++;
        char name[NAME_MAX_LEN];
        if (!read_name(&c, name))
            return 0;
        if (!is_allowed(name, allowed))
            return fail(&c, "element <%s> is not among those allowed", name);
        if (depth == 0 && ++roots > 1)
            return fail(&c, "a second root element <%s>", name);
        char attrs[ATTR_MAX][NAME_MAX_LEN];
        int nattrs = 0;
        for (;;) {
            const char *before = c.p;
            skip_space(&c);
            if (*c.p == '/' && c.p[1] == '>') {
                c.p += 2;
                break;
            }
            if (*c.p == '>') {
                c.p++;
                if (depth >= DEPTH_MAX)
                    return fail(&c, "nesting deeper than %d", DEPTH_MAX);
                strcpy(stack[depth++], name);
                break;
            }
            if (c.p == before)
                return fail(&c, "expected a space before an attribute of <%s>", name);
            char an[NAME_MAX_LEN];
            if (!read_name(&c, an))
                return 0;
            for (int i = 0; i < nattrs; i++)
                if (!strcmp(attrs[i], an))
                    return fail(&c, "attribute %s repeated in <%s>", an, name);
            if (nattrs >= ATTR_MAX)
                return fail(&c, "more than %d attributes", ATTR_MAX);
            strcpy(attrs[nattrs++], an);
            skip_space(&c);
            if (*c.p != '=')
                return fail(&c, "expected '=' after attribute %s", an);
            c.p++;
            skip_space(&c);
            char q = *c.p;
            if (q != '"' && q != '\'')
                return fail(&c, "attribute %s's value is not quoted", an);
            c.p++;
            while (*c.p != q) {
                if (*c.p == '\0' || *c.p == '<')
                    return fail(&c, "attribute %s's value holds '<' or does not end", an);
                if (*c.p == '&') {
                    if (!reference(&c))
                        return 0;
                } else {
                    c.p++;
                }
            }
            c.p++;
        }
    }
    if (depth)
        return fail(&c, "<%s> is never closed", stack[depth - 1]);
    if (roots != 1)
        return fail(&c, "no root element");
    return 1;
}
