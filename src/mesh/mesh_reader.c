/* mesh_reader.c: the line cursor, number parsing, mesh builder and exact
 * vertex map shared by the mesh readers (see mesh_reader.h). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mesh/mesh_reader.h"
#include "posedrop/tolerances.h"

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

int pd_parse_double(const char *s, size_t n, double *out)
{
    /* strtod needs a terminated string; no genuine number is this long. */
    char buf[128];
    if (n == 0 || n >= sizeof buf)
        return PD_NUM_BAD;
    memcpy(buf, s, n);
    buf[n] = '\0';
    char *stop;
    errno = 0;
    double v = strtod(buf, &stop);
    if (stop != buf + n)
        return PD_NUM_BAD;
    if (!isfinite(v))
        return PD_NUM_NONFINITE;
    *out = v;
    return PD_NUM_OK;
}

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
        return pd_text_fail(t, diag, PD_ERR_NONFINITE, "non-finite %s %s", what,
                            pd_text_show(shown, sizeof shown, s, n));
    *out = v;
    return PD_OK;
}

/* --- mesh builder ----------------------------------------------------------- */

/* Grows *p to hold need elements; capacity doubles so pushes are amortised O(1). */
static pd_status grow(void **p, int *cap, long long need, size_t elem)
{
    if (need <= *cap)
        return PD_OK;
    if (need > PD_MAX_ELEMENTS)
        return PD_ERR_RANGE;
    long long c = *cap < 64 ? 64 : 2LL * *cap;
    if (c < need)
        c = need;
    if (c > PD_MAX_ELEMENTS)
        c = PD_MAX_ELEMENTS;
    if ((size_t)c > SIZE_MAX / elem)
        return PD_ERR_NOMEM;
    void *q = realloc(*p, (size_t)c * elem);
    if (!q)
        return PD_ERR_NOMEM;
    *p = q;
    *cap = (int)c;
    return PD_OK;
}

pd_status pd_build_reserve(pd_build *b, long long nverts, long long ntris)
{
    void *v = b->verts, *t = b->tris;
    pd_status st = grow(&v, &b->cverts, nverts, sizeof *b->verts);
    b->verts = v;
    if (st == PD_OK)
        st = grow(&t, &b->ctris, ntris, sizeof *b->tris);
    b->tris = t;
    return st;
}

pd_status pd_build_vert(pd_build *b, pd_vec3 v)
{
    if (b->nverts == b->cverts) {
        void *p = b->verts;
        pd_status st = grow(&p, &b->cverts, (long long)b->nverts + 1, sizeof *b->verts);
        b->verts = p;
        if (st != PD_OK)
            return st;
    }
    b->verts[b->nverts++] = v;
    return PD_OK;
}

pd_status pd_build_tri(pd_build *b, int i0, int i1, int i2)
{
    if (b->ntris == b->ctris) {
        void *p = b->tris;
        pd_status st = grow(&p, &b->ctris, (long long)b->ntris + 1, sizeof *b->tris);
        b->tris = p;
        if (st != PD_OK)
            return st;
    }
    b->tris[b->ntris][0] = i0;
    b->tris[b->ntris][1] = i1;
    b->tris[b->ntris][2] = i2;
    b->ntris++;
    return PD_OK;
}

pd_status pd_build_finish(pd_build *b, pd_mesh **mesh)
{
    pd_mesh *m = malloc(sizeof *m);
    if (!m)
        return PD_ERR_NOMEM;
    m->nverts = b->nverts;
    m->verts = b->verts;
    m->ntris = b->ntris;
    m->tris = b->tris;
    memset(b, 0, sizeof *b);
    *mesh = m;
    return PD_OK;
}

void pd_build_free(pd_build *b)
{
    free(b->verts);
    free(b->tris);
    memset(b, 0, sizeof *b);
}

/* --- exact vertex map --------------------------------------------------------- */

static uint64_t coord_bits(double c)
{
    /* Adding +0.0 turns -0.0 into +0.0 and changes nothing else, so the two
     * zeros, which compare equal, also hash and match alike. */
    double z = c + 0.0;
    uint64_t u;
    memcpy(&u, &z, sizeof u);
    return u;
}

static size_t vert_hash(pd_vec3 v)
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    uint64_t k[3] = {coord_bits(v.x), coord_bits(v.y), coord_bits(v.z)};
    for (int i = 0; i < 3; i++) {
        h ^= k[i];
        h *= 0xbf58476d1ce4e5b9ULL;
        h ^= h >> 31;
    }
    return (size_t)h;
}

static int same_bits(pd_vec3 a, pd_vec3 b)
{
    return coord_bits(a.x) == coord_bits(b.x) && coord_bits(a.y) == coord_bits(b.y) &&
           coord_bits(a.z) == coord_bits(b.z);
}

static int *new_slots(size_t cap)
{
    int *s = malloc(cap * sizeof *s);
    if (s)
        memset(s, 0xff, cap * sizeof *s); /* all -1 */
    return s;
}

pd_status pd_vmap_init(pd_vmap *m, size_t expected)
{
    /* At most half full: linear probes stay short. */
    size_t cap = 64;
    while (cap / 2 < expected && cap < SIZE_MAX / 4 / sizeof(int))
        cap *= 2;
    m->slot = new_slots(cap);
    m->mask = cap - 1;
    m->count = 0;
    return m->slot ? PD_OK : PD_ERR_NOMEM;
}

static void insert(int *slot, size_t mask, const pd_vec3 *verts, int i)
{
    size_t h = vert_hash(verts[i]) & mask;
    while (slot[h] >= 0)
        h = (h + 1) & mask;
    slot[h] = i;
}

int pd_vmap_find_or_add(pd_vmap *m, const pd_vec3 *verts, int i)
{
    size_t h = vert_hash(verts[i]) & m->mask;
    for (; m->slot[h] >= 0; h = (h + 1) & m->mask)
        if (same_bits(verts[m->slot[h]], verts[i]))
            return m->slot[h];
    if (2 * (m->count + 1) > m->mask + 1) {
        size_t cap = 2 * (m->mask + 1);
        int *s = new_slots(cap);
        if (!s)
            return -1;
        for (size_t k = 0; k <= m->mask; k++)
            if (m->slot[k] >= 0)
                insert(s, cap - 1, verts, m->slot[k]);
        free(m->slot);
        m->slot = s;
        m->mask = cap - 1;
    }
    insert(m->slot, m->mask, verts, i);
    m->count++;
    return i;
}

void pd_vmap_free(pd_vmap *m)
{
    free(m->slot);
    m->slot = NULL;
}
