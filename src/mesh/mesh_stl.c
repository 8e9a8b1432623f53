/* mesh_stl.c: the STL reader, ASCII and binary.
 *
 * STL is a triangle soup: every triangle repeats its corners. Corners that are
 * bit-identical are merged while reading so the result is an indexed mesh;
 * near-identical ones are left to pd_mesh_weld, which knows the part's size. */
#include <stdint.h>
#include <string.h>
#include "mesh/mesh_reader.h"
#include "base/vec3.h"
#include "posedrop/tolerances.h"

_Static_assert(sizeof(float) == 4, "binary STL decoding needs a 32-bit float");

enum { HEADER = 80, COUNT_END = 84, RECORD = 50 };

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

static double le_float(const unsigned char *p)
{
    /* Assembling the integer by bytes makes the decoding independent of the
     * host's byte order; the bits are then those of an IEEE float32. */
    uint32_t u = le32(p);
    float f;
    memcpy(&f, &u, sizeof f);
    return (double)f;
}

int pd_stl_is_solid(const char *s, size_t n)
{
    if (n > 3 && memcmp(s, "\xEF\xBB\xBF", 3) == 0) {
        s += 3;
        n -= 3;
    }
    return pd_text_is(s, n, "solid");
}

static int starts_with_solid(const unsigned char *d, size_t size)
{
    size_t i = 0;
    while (i < size && (d[i] == ' ' || d[i] == '\t' || d[i] == '\r' || d[i] == '\n'))
        i++;
    return size - i >= 5 && pd_text_is((const char *)d + i, 5, "solid");
}

/* The first word of each line in the file's first bytes: a "solid" line
 * followed by a "facet" or "endsolid" line is ASCII STL's structure, which
 * no binary STL shows (its header may start with "solid", but what follows
 * is floats). Looking past the first line finds it after a comment line, and
 * a NUL byte further on does not hide it. */
static int has_ascii_structure(const unsigned char *d, size_t size)
{
    /* Far more than a "solid" line with a long name and the first facet. */
    enum { WINDOW = 1 << 14 };
    pd_text t;
    pd_text_init(&t, d, size < WINDOW ? size : WINDOW, "", 0, 0);
    int solid = 0;
    const char *s;
    size_t n;
    while (pd_text_next_line(&t) && pd_text_token(&t, &s, &n)) {
        if (pd_stl_is_solid(s, n))
            solid = 1;
        else if (solid && (pd_text_is(s, n, "facet") || pd_text_is(s, n, "endsolid")))
            return 1;
    }
    return 0;
}

/* What a file that is not binary STL looks like, for the messages: NULL
 * when its first bytes hold a byte no text has (a NUL or another control
 * byte: binary data), else by its first word past '#' comment lines:
 * "ASCII STL", "OFF", "OBJ" or "text". Bytes 80-83 of text make a triangle
 * count of at least 0x09090909, beyond PD_MAX_ELEMENTS, so no valid binary
 * STL passes for text here. */
static const char *text_kind(const unsigned char *d, size_t size)
{
    enum { LOOK = 4096 };
    size_t look = size < LOOK ? size : LOOK;
    if (look == 0)
        return NULL;
    for (size_t i = 0; i < look; i++)
        if (d[i] < 0x20 && d[i] != '\t' && d[i] != '\n' && d[i] != '\v' && d[i] != '\f' &&
            d[i] != '\r')
            return NULL;
    pd_text t;
    pd_text_init(&t, d, size, "", '#', 0);
    const char *s;
    size_t n;
    if (!pd_text_token_any(&t, &s, &n))
        return "text";
    if (pd_stl_is_solid(s, n))
        return "ASCII STL";
    if (pd_off_is_keyword(s, n))
        return "OFF";
    if (pd_obj_is_keyword(s, n))
        return "OBJ";
    return "text";
}

int pd_stl_is_binary(const unsigned char *data, size_t size)
{
    /* Binary STL has no magic number; its size formula is its signature (no
     * text matches it: bytes 80-83 of text make a count of at least
     * 0x09090909, gigabytes beyond any file read). Exporters do write
     * "solid" at the start of binary headers, so that word alone decides
     * nothing. Otherwise text: a file starting with "solid" without NUL
     * bytes, or one with ASCII STL's structure. */
    if (size >= COUNT_END && COUNT_END + (uint64_t)RECORD * le32(data + HEADER) == size)
        return 1;
    const char *kind;
    int text = (starts_with_solid(data, size) && memchr(data, 0, size) == NULL) ||
               has_ascii_structure(data, size) ||
               ((kind = text_kind(data, size)) != NULL && strcmp(kind, "ASCII STL") == 0);
    return !text;
}

/* Adds a corner, merged with a bit-identical earlier one; its index or -1. */
static int add_corner(pd_build *b, pd_vmap *map, pd_vec3 v, pd_status *st)
{
    *st = pd_build_vert(b, v);
    if (*st != PD_OK)
        return -1;
    int i = pd_vmap_find_or_add(map, b->verts, b->nverts - 1);
    if (i < 0) {
        *st = PD_ERR_NOMEM;
        return -1;
    }
    if (i != b->nverts - 1)
        b->nverts--;
    return i;
}

/* Binary STL's header against the file's size: the first 84 bytes and the
 * size are all it reads, so a file's start can be checked before the rest
 * of it is read (pd_stl_check_head). Text that is no ASCII STL (an OBJ or
 * OFF file given as STL, text without "solid") is named for what it looks
 * like instead of read as a triangle count. */
static pd_status binary_header(const unsigned char *d, size_t avail, size_t size,
                               const char *name, pd_diag *diag, uint32_t *count)
{
    const char *kind = text_kind(d, avail);
    int fits = size >= COUNT_END && COUNT_END + (uint64_t)RECORD * le32(d + HEADER) == size;
    if (kind && !fits)
        return pd_fail(diag, PD_ERR_FORMAT,
                       "%s: does not look like binary STL (%zu bytes of text, not 84 plus 50 per "
                       "triangle) nor like ASCII STL (no 'solid' line first): it looks like %s",
                       name, size, strcmp(kind, "text") == 0 ? "text of no mesh format" : kind);
    if (size < COUNT_END)
        return pd_fail(diag, PD_ERR_PARSE,
                       "%s: truncated binary STL: %zu bytes, the header alone needs %d", name,
                       size, COUNT_END);
    uint32_t n = *count = le32(d + HEADER);
    if (n > PD_MAX_ELEMENTS)
        return pd_fail(diag, PD_ERR_RANGE,
                       "%s: binary STL declares %lu triangles; the limit is %d", name,
                       (unsigned long)n, PD_MAX_ELEMENTS);
    size_t have = (size - COUNT_END) / RECORD;
    if (have < n)
        return pd_fail(diag, PD_ERR_PARSE,
                       "%s: truncated binary STL: header declares %lu triangles (%llu bytes) "
                       "but the file has %zu bytes (%zu whole triangles)",
                       name, (unsigned long)n,
                       (unsigned long long)COUNT_END + (unsigned long long)RECORD * n, size, have);
    if (n == 0)
        return pd_fail(diag, PD_ERR_PARSE, "%s: no faces (binary STL with 0 triangles)", name);
    return PD_OK;
}

pd_status pd_stl_check_head(const unsigned char *head, size_t n, size_t size, const char *name,
                            pd_diag *diag)
{
    /* Only a start that both the head and the whole file send to the binary
     * reader: a NUL byte among the first bytes (never text), without ASCII
     * STL's structure (looked for in a window the head holds). */
    enum { LOOK = 4096 };
    if (n < COUNT_END || COUNT_END + (uint64_t)RECORD * le32(head + HEADER) == size ||
        !memchr(head, 0, n < LOOK ? n : LOOK) || has_ascii_structure(head, n))
        return PD_OK;
    uint32_t count;
    return binary_header(head, n, size, name, diag, &count);
}

static pd_status read_binary(const unsigned char *d, size_t size, const char *name, double scale,
                             pd_build *b, pd_vmap *map, pd_diag *diag)
{
    uint32_t n;
    pd_status st = binary_header(d, size, size, name, diag, &n);
    if (st != PD_OK)
        return st;
    /* A closed mesh has about half as many vertices as triangles. */
    st = pd_build_reserve(b, n / 2 + 3, n);
    if (st == PD_OK)
        st = pd_vmap_init(map, n / 2 + 3);
    if (st != PD_OK)
        return pd_fail(diag, st, "%s: out of memory for %lu triangles", name, (unsigned long)n);
    for (uint32_t k = 0; k < n; k++) {
        const unsigned char *r = d + COUNT_END + (size_t)k * RECORD + 12; /* skip the normal */
        int idx[3];
        for (int c = 0; c < 3; c++) {
            pd_vec3 v = {le_float(r + 12 * c) * scale, le_float(r + 12 * c + 4) * scale,
                         le_float(r + 12 * c + 8) * scale};
            if (!v3_isfinite(v))
                return pd_fail(diag, PD_ERR_NONFINITE,
                               "%s: triangle %lu: non-finite coordinate in corner %d", name,
                               (unsigned long)k + 1, c + 1);
            idx[c] = add_corner(b, map, v, &st);
            if (idx[c] < 0)
                return pd_fail(diag, st, "%s: out of memory at triangle %lu", name,
                               (unsigned long)k + 1);
        }
        if ((st = pd_build_tri(b, idx[0], idx[1], idx[2])) != PD_OK)
            return pd_fail(diag, st, "%s: out of memory at triangle %lu", name,
                           (unsigned long)k + 1);
    }
    if (size > COUNT_END + (size_t)RECORD * n)
        pd_warn(diag, "%s: %zu bytes after the %lu triangles of binary STL ignored", name,
                size - COUNT_END - (size_t)RECORD * n, (unsigned long)n);
    return PD_OK;
}

/* The next token must be the keyword. */
static pd_status expect(pd_text *t, pd_diag *diag, const char *word)
{
    const char *s;
    size_t n;
    char shown[48];
    if (!pd_text_token_any(t, &s, &n))
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected '%s', found end of file", word);
    if (!pd_text_is(s, n, word))
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected '%s', found %s", word,
                            pd_text_show(shown, sizeof shown, s, n));
    return PD_OK;
}

static pd_status read_facet(pd_text *t, pd_diag *diag, double scale, pd_build *b, pd_vmap *map)
{
    /* "facet" has been read. The normal is not used (the winding decides the
     * orientation) and some exporters write "nan" there for degenerate
     * triangles, so its three tokens are skipped, not checked. */
    pd_status st = expect(t, diag, "normal");
    for (int k = 0; k < 3 && st == PD_OK; k++) {
        const char *s;
        size_t n;
        if (!pd_text_token_any(t, &s, &n))
            st = pd_text_fail(t, diag, PD_ERR_PARSE, "expected a normal, found end of file");
    }
    if (st == PD_OK)
        st = expect(t, diag, "outer");
    if (st == PD_OK)
        st = expect(t, diag, "loop");
    int idx[3];
    for (int c = 0; c < 3 && st == PD_OK; c++) {
        pd_vec3 v;
        st = expect(t, diag, "vertex");
        if (st == PD_OK)
            st = pd_text_coord(t, diag, "an x coordinate", scale, &v.x);
        if (st == PD_OK)
            st = pd_text_coord(t, diag, "a y coordinate", scale, &v.y);
        if (st == PD_OK)
            st = pd_text_coord(t, diag, "a z coordinate", scale, &v.z);
        if (st == PD_OK && (idx[c] = add_corner(b, map, v, &st)) < 0)
            return pd_text_fail(t, diag, st, st == PD_ERR_RANGE ? "too many vertices" : "out of memory");
    }
    if (st == PD_OK)
        st = expect(t, diag, "endloop");
    if (st == PD_OK)
        st = expect(t, diag, "endfacet");
    if (st == PD_OK && (st = pd_build_tri(b, idx[0], idx[1], idx[2])) != PD_OK)
        return pd_text_fail(t, diag, st, st == PD_ERR_RANGE ? "too many triangles" : "out of memory");
    return st;
}

static pd_status read_ascii(pd_cancel_flag *cancel, const unsigned char *d, size_t size,
                            const char *name, double scale,
                            pd_build *b, pd_vmap *map, pd_diag *diag)
{
    /* Text has no NUL byte; one (a damaged file) is named with its line
     * rather than left to look like a bad token. */
    const unsigned char *nul = memchr(d, 0, size);
    if (nul) {
        long long line = 1;
        for (const unsigned char *c = d; c < nul; c++)
            line += *c == '\n';
        return pd_fail(diag, PD_ERR_PARSE, "%s:%lld: a NUL byte in ASCII STL, which is text", name,
                       line);
    }
    /* '#' comment lines are no part of STL, but some tools write one before
     * "solid"; the format detection skips them too. */
    pd_text t;
    pd_text_init(&t, d, size, name, '#', 0);
    t.cancel = cancel;
    pd_status st = pd_vmap_init(map, 0);
    if (st != PD_OK)
        return pd_fail(diag, st, "%s: out of memory", name);
    const char *s;
    size_t n;
    char shown[48];
    /* One or more solids, each "solid [name]" ... "endsolid [name]". */
    while (pd_text_token_any(&t, &s, &n)) {
        if (!pd_stl_is_solid(s, n))
            return pd_text_fail(&t, diag, PD_ERR_PARSE, "expected 'solid'%s, found %s",
                                b->ntris ? " or end of file" : "",
                                pd_text_show(shown, sizeof shown, s, n));
        t.tok = t.eol; /* the solid's name */
        for (;;) {
            if (!pd_text_token_any(&t, &s, &n))
                return pd_text_fail(&t, diag, PD_ERR_PARSE,
                                    "expected 'facet' or 'endsolid', found end of file");
            if (pd_text_is(s, n, "endsolid"))
                break;
            if (!pd_text_is(s, n, "facet"))
                return pd_text_fail(&t, diag, PD_ERR_PARSE,
                                    "expected 'facet' or 'endsolid', found %s",
                                    pd_text_show(shown, sizeof shown, s, n));
            if ((st = read_facet(&t, diag, scale, b, map)) != PD_OK)
                return st;
        }
        t.tok = t.eol; /* the name after endsolid */
    }
    if (b->ntris == 0)
        return pd_fail(diag, PD_ERR_PARSE, "%s: no faces (ASCII STL without facets)", name);
    return PD_OK;
}

pd_status pd_stl_read(const unsigned char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel)
{
    pd_build b = {0};
    pd_vmap map = {0};
    pd_status st = pd_stl_is_binary(data, size)
                       ? read_binary(data, size, name, scale, &b, &map, diag)
                       : read_ascii(cancel, data, size, name, scale, &b, &map, diag);
    pd_vmap_free(&map);
    if (st == PD_OK && (st = pd_build_finish(&b, mesh)) != PD_OK)
        pd_fail(diag, st, "%s: out of memory", name);
    if (st != PD_OK)
        pd_build_free(&b);
    return st;
}
