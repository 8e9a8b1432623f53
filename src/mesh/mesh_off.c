/* mesh_off.c: the OFF reader (Geomview's Object File Format, ASCII).
 *
 * Records are lines: a vertex line starts with its three coordinates and a
 * face line with its vertex count and indices; whatever follows (colours,
 * normals, texture coordinates) is ignored, but a vertex line's extra
 * tokens must be numbers (pd_vertex_rest, as in OBJ). '#' starts a comment
 * anywhere. */
#include <string.h>
#include "mesh/mesh_reader.h"
#include "posedrop/tolerances.h"

/* Which prefixes of [ST][C][N][4][n]OFF a header keyword carries. */
typedef struct off_kind {
    int four; /* 4OFF: homogeneous 4-D coordinates */
    int ndim; /* nOFF: the dimension follows the keyword */
} off_kind;

static int parse_keyword(const char *s, size_t n, off_kind *k)
{
    size_t i = 0;
    memset(k, 0, sizeof *k);
    if (n - i >= 2 && s[i] == 'S' && s[i + 1] == 'T')
        i += 2;
    if (i < n && s[i] == 'C')
        i++;
    if (i < n && s[i] == 'N')
        i++;
    if (i < n && s[i] == '4') {
        k->four = 1;
        i++;
    }
    if (i < n && s[i] == 'n') {
        k->ndim = 1;
        i++;
    }
    return pd_text_is(s + i, n - i, "OFF");
}

int pd_off_is_keyword(const char *s, size_t n)
{
    off_kind k;
    return parse_keyword(s, n, &k);
}

/* A non-negative integer token; PD_ERR_PARSE naming what was expected. */
static pd_status read_count(pd_text *t, pd_diag *diag, int any_line, const char *what,
                            long long *out)
{
    const char *s = NULL;
    size_t n = 0;
    char shown[48];
    int have = any_line ? pd_text_token_any(t, &s, &n) : pd_text_token(t, &s, &n);
    if (!have)
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected %s, found end of %s", what,
                            any_line ? "file" : "line");
    if (!pd_parse_int(s, n, out) || *out < 0)
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected %s, found %s", what,
                            pd_text_show(shown, sizeof shown, s, n));
    return PD_OK;
}

/* The header keyword, the first token of the file. */
static pd_status header_keyword(pd_text *t, pd_diag *diag, off_kind *kind)
{
    const char *s;
    size_t n;
    char shown[48];
    if (!pd_text_token_any(t, &s, &n))
        return pd_fail(diag, PD_ERR_PARSE, "%s: expected OFF header, found an empty file", t->name);
    if (!parse_keyword(s, n, kind))
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected OFF header, found %s",
                            pd_text_show(shown, sizeof shown, s, n));
    return PD_OK;
}

pd_status pd_off_check_head(const char *head, size_t n, const char *name, pd_diag *diag)
{
    pd_text t;
    pd_text_init(&t, head, n, name, '#', 0);
    pd_text probe = t;
    const char *s;
    size_t len;
    off_kind kind;
    /* No token yet (a head of comments): the rest decides. */
    if (!pd_text_token_any(&probe, &s, &len))
        return PD_OK;
    return header_keyword(&t, diag, &kind);
}

static pd_status read_header(pd_text *t, pd_diag *diag, long long *nv, long long *nf)
{
    const char *s;
    size_t n;
    char shown[48];
    off_kind kind;
    pd_status hst = header_keyword(t, diag, &kind);
    if (hst != PD_OK)
        return hst;
    if (kind.four)
        return pd_text_fail(t, diag, PD_ERR_FORMAT,
                            "4OFF (4-D homogeneous vertices) is not supported, only 3-D OFF");
    /* Peek at the rest of the header line for the binary variant. */
    pd_text save = *t;
    if (pd_text_token(t, &s, &n) && pd_text_is(s, n, "BINARY"))
        return pd_text_fail(t, diag, PD_ERR_FORMAT,
                            "binary OFF is not supported; convert it to ASCII OFF");
    *t = save;
    if (kind.ndim) {
        long long dim;
        pd_status st = read_count(t, diag, 1, "the dimension of nOFF", &dim);
        if (st != PD_OK)
            return st;
        if (dim != 3)
            return pd_text_fail(t, diag, PD_ERR_FORMAT,
                                "nOFF of dimension %lld is not supported, only 3", dim);
    }
    pd_status st = read_count(t, diag, 1, "the vertex count", nv);
    if (st == PD_OK)
        st = read_count(t, diag, 1, "the face count", nf);
    if (st != PD_OK)
        return st;
    /* The edge count is optional and must share the face count's line, or a
     * first vertex coordinate would be taken for it. */
    long long ne;
    if (pd_text_token(t, &s, &n)) {
        if (!pd_parse_int(s, n, &ne) || ne < 0)
            return pd_text_fail(t, diag, PD_ERR_PARSE, "expected the edge count, found %s",
                                pd_text_show(shown, sizeof shown, s, n));
        if (pd_text_token(t, &s, &n))
            return pd_text_fail(t, diag, PD_ERR_PARSE,
                                "expected end of line after the counts, found %s",
                                pd_text_show(shown, sizeof shown, s, n));
    }
    if (*nv > PD_MAX_ELEMENTS || *nf > PD_MAX_ELEMENTS)
        return pd_text_fail(t, diag, PD_ERR_RANGE,
                            "header declares %lld vertices and %lld faces; the limit is %d each",
                            *nv, *nf, PD_MAX_ELEMENTS);
    /* Smallest records: "0 0 0\n" and a face "0\n" (refused by the face's
     * reader, which says why); the last may lack its '\n'. */
    long long need = 6 * *nv + 2 * *nf - 1;
    if (need > 0 && (unsigned long long)need > pd_text_left(t))
        return pd_text_fail(t, diag, PD_ERR_PARSE,
                            "header declares %lld vertices and %lld faces, but only %zu bytes "
                            "follow (truncated file?)",
                            *nv, *nf, pd_text_left(t));
    return PD_OK;
}

static pd_status read_vertex(pd_text *t, pd_diag *diag, double scale, pd_vec3 *v)
{
    double c[3];
    char shown[48];
    for (int k = 0; k < 3; k++) {
        const char *s;
        size_t n;
        if (!pd_text_token(t, &s, &n))
            return pd_text_fail(t, diag, PD_ERR_PARSE, "expected 3 coordinates, found %d", k);
        int rc = pd_parse_double(s, n, &c[k]);
        if (rc == PD_NUM_BAD)
            return pd_text_fail(t, diag, PD_ERR_PARSE, "expected a coordinate, found %s",
                                pd_text_show(shown, sizeof shown, s, n));
        if (rc == PD_NUM_NONFINITE)
            return pd_text_fail(t, diag, PD_ERR_NONFINITE, "non-finite coordinate %s",
                                pd_text_show(shown, sizeof shown, s, n));
        if (rc == PD_NUM_TINY)
            return pd_text_fail(t, diag, PD_ERR_RANGE, "coordinate %s is non-zero but below the "
                                "smallest normal double, 2.2e-308",
                                pd_text_show(shown, sizeof shown, s, n));
    }
    pd_status st = pd_vertex_rest(t, diag);
    if (st != PD_OK)
        return st;
    /* Scales are at most 1 (metres per unit), so scaling cannot overflow. */
    v->x = c[0] * scale;
    v->y = c[1] * scale;
    v->z = c[2] * scale;
    return PD_OK;
}

static pd_status read_face(pd_text *t, pd_diag *diag, int nverts, pd_build *b)
{
    const char *s;
    size_t n;
    char shown[48];
    long long k;
    pd_status st = read_count(t, diag, 0, "a face vertex count", &k);
    if (st != PD_OK)
        return st;
    if (k < 3)
        return pd_text_fail(t, diag, PD_ERR_PARSE, "face with %lld vertices (at least 3 needed)", k);
    if (k > PD_MAX_FACE_VERTICES)
        return pd_text_fail(t, diag, PD_ERR_RANGE, "face with %lld vertices; the limit is %d", k,
                            PD_MAX_FACE_VERTICES);
    int first = 0, prev = 0;
    for (long long j = 0; j < k; j++) {
        long long idx;
        if (!pd_text_token(t, &s, &n))
            return pd_text_fail(t, diag, PD_ERR_PARSE,
                                "expected %lld vertex indices, found %lld", k, j);
        if (!pd_parse_int(s, n, &idx))
            return pd_text_fail(t, diag, PD_ERR_PARSE, "expected a vertex index, found %s",
                                pd_text_show(shown, sizeof shown, s, n));
        if (idx < 0 || idx >= nverts)
            return pd_text_fail(t, diag, PD_ERR_RANGE,
                                "vertex index %lld out of range (%d vertices, indices from 0)",
                                idx, nverts);
        if (j == 0)
            first = (int)idx;
        else if (j >= 2 && (st = pd_build_tri(b, first, prev, (int)idx)) != PD_OK)
            return st == PD_ERR_RANGE
                       ? pd_text_fail(t, diag, st, "more than %d triangles", PD_MAX_ELEMENTS)
                       : pd_text_fail(t, diag, st, "out of memory");
        prev = (int)idx;
    }
    return PD_OK;
}

pd_status pd_off_read(const char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel)
{
    pd_text t;
    pd_text_init(&t, data, size, name, '#', 0);
    t.cancel = cancel;
    long long nv, nf;
    pd_status st = read_header(&t, diag, &nv, &nf);
    if (st != PD_OK)
        return st;
    if (nf == 0)
        return pd_text_fail(&t, diag, PD_ERR_PARSE, "no faces (the header declares 0)");
    pd_build b = {0};
    if (pd_build_reserve(&b, nv, nf) != PD_OK) {
        pd_build_free(&b);
        return pd_fail(diag, PD_ERR_NOMEM, "%s: out of memory for %lld vertices", name, nv);
    }
    for (long long i = 0; i < nv && st == PD_OK; i++) {
        pd_vec3 v;
        if (!pd_text_next_line(&t)) {
            st = pd_text_fail(&t, diag, PD_ERR_PARSE,
                              "expected %lld vertices, found %lld before the end of file", nv, i);
            break;
        }
        st = read_vertex(&t, diag, scale, &v);
        if (st == PD_OK)
            st = pd_build_vert(&b, v);
    }
    for (long long i = 0; i < nf && st == PD_OK; i++) {
        if (!pd_text_next_line(&t)) {
            st = pd_text_fail(&t, diag, PD_ERR_PARSE,
                              "expected %lld faces, found %lld before the end of file", nf, i);
            break;
        }
        st = read_face(&t, diag, b.nverts, &b);
    }
    const char *s;
    size_t n;
    char shown[48];
    if (st == PD_OK && pd_text_next_line(&t) && pd_text_token(&t, &s, &n))
        st = pd_text_fail(&t, diag, PD_ERR_PARSE,
                          "expected end of file after %lld faces, found %s", nf,
                          pd_text_show(shown, sizeof shown, s, n));
    if (st == PD_OK)
        st = pd_build_finish(&b, mesh);
    if (st != PD_OK)
        pd_build_free(&b);
    return st;
}
