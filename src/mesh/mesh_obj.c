/* mesh_obj.c: the Wavefront OBJ reader (geometry only).
 *
 * Only "v" and "f" lines make the mesh. Texture and normal indices of face
 * corners are checked for form and ignored; so are the lines for texture
 * coordinates, normals, groups, smoothing, materials and free-form geometry.
 * The optional w of "v x y z w" is ignored: it weights rational curves, and
 * some exporters put other data there (a colour), so dividing by it would
 * move vertices for no gain. Like OFF's extra vertex data it must be numbers
 * (pd_vertex_rest). */
#include <string.h>
#include "mesh/mesh_reader.h"
#include "posedrop/tolerances.h"

static const char *const ignored[] = {
    "vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib", "l", "p",
    /* free-form geometry and display attributes */
    "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm", "trim", "hole",
    "scrv", "sp", "end", "con", "mg", "bevel", "c_interp", "d_interp", "lod", "maplib",
    "usemap", "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh",
};

static int is_ignored(const char *s, size_t n)
{
    for (size_t i = 0; i < sizeof ignored / sizeof ignored[0]; i++)
        if (n == strlen(ignored[i]) && memcmp(s, ignored[i], n) == 0)
            return 1;
    return 0;
}

int pd_obj_is_keyword(const char *s, size_t n)
{
    return (n == 1 && (s[0] == 'v' || s[0] == 'f')) || is_ignored(s, n);
}

/* A word that could be some exporter's own keyword, as opposed to stray
 * numbers or binary bytes, which are clearly not OBJ. */
static int looks_like_keyword(const char *s, size_t n)
{
    if (!((s[0] >= 'a' && s[0] <= 'z') || (s[0] >= 'A' && s[0] <= 'Z')))
        return 0;
    for (size_t i = 1; i < n; i++) {
        char c = s[i];
        if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
              c == '_'))
            return 0;
    }
    return 1;
}

/* "i", "i/t", "i/t/n" or "i//n": the vertex index, 0-based. Relative indices
 * (-1 is the last vertex so far) are resolved against nverts. */
static pd_status corner_index(pd_text *t, pd_diag *diag, const char *s, size_t n, int nverts,
                              int *out)
{
    char shown[48];
    const char *slash = memchr(s, '/', n);
    size_t head = slash ? (size_t)(slash - s) : n;
    long long v, other;
    if (!pd_parse_int(s, head, &v))
        return pd_text_fail(t, diag, PD_ERR_PARSE, "expected a vertex index, found %s",
                            pd_text_show(shown, sizeof shown, s, n));
    /* The texture and normal parts: each empty or an integer, at most two. */
    for (int part = 0; slash && part < 2; part++) {
        const char *from = slash + 1;
        size_t left = n - (size_t)(from - s);
        slash = memchr(from, '/', left);
        size_t len = slash ? (size_t)(slash - from) : left;
        if (len > 0 && !pd_parse_int(from, len, &other))
            return pd_text_fail(t, diag, PD_ERR_PARSE,
                                "expected a face corner i, i/t, i/t/n or i//n, found %s",
                                pd_text_show(shown, sizeof shown, s, n));
    }
    if (slash)
        return pd_text_fail(t, diag, PD_ERR_PARSE,
                            "expected a face corner i, i/t, i/t/n or i//n, found %s",
                            pd_text_show(shown, sizeof shown, s, n));
    if (v == 0)
        return pd_text_fail(t, diag, PD_ERR_RANGE, "vertex index 0 (OBJ indices start at 1)");
    long long i = v > 0 ? v - 1 : nverts + v;
    if (v < 0 && i < 0)
        return pd_text_fail(t, diag, PD_ERR_RANGE,
                            "relative vertex index %lld reaches before the first vertex "
                            "(%d vertices so far)", v, nverts);
    if (i >= nverts)
        return pd_text_fail(t, diag, PD_ERR_RANGE,
                            "vertex index %lld out of range (%d vertices so far)", v, nverts);
    *out = (int)i;
    return PD_OK;
}

static pd_status read_face(pd_text *t, pd_diag *diag, pd_build *b)
{
    const char *s;
    size_t n;
    int first = 0, prev = 0, k = 0;
    pd_status st;
    while (pd_text_token(t, &s, &n)) {
        int i = 0;
        if (k == PD_MAX_FACE_VERTICES)
            return pd_text_fail(t, diag, PD_ERR_RANGE, "face with more than %d vertices",
                                PD_MAX_FACE_VERTICES);
        if ((st = corner_index(t, diag, s, n, b->nverts, &i)) != PD_OK)
            return st;
        if (k == 0)
            first = i;
        else if (k >= 2 && (st = pd_build_tri(b, first, prev, i)) != PD_OK)
            return st == PD_ERR_RANGE
                       ? pd_text_fail(t, diag, st, "more than %d triangles", PD_MAX_ELEMENTS)
                       : pd_text_fail(t, diag, st, "out of memory");
        prev = i;
        k++;
    }
    if (k < 3)
        return pd_text_fail(t, diag, PD_ERR_PARSE, "face with %d vertices (at least 3 needed)", k);
    return PD_OK;
}

static pd_status read_vertex(pd_text *t, pd_diag *diag, double scale, pd_build *b)
{
    pd_vec3 v;
    pd_status st = pd_text_coord(t, diag, "an x coordinate", scale, &v.x);
    if (st == PD_OK)
        st = pd_text_coord(t, diag, "a y coordinate", scale, &v.y);
    if (st == PD_OK)
        st = pd_text_coord(t, diag, "a z coordinate", scale, &v.z);
    if (st == PD_OK)
        st = pd_vertex_rest(t, diag);
    if (st == PD_OK && (st = pd_build_vert(b, v)) != PD_OK)
        return st == PD_ERR_RANGE
                   ? pd_text_fail(t, diag, st, "more than %d vertices", PD_MAX_ELEMENTS)
                   : pd_text_fail(t, diag, st, "out of memory");
    return st;
}

/* A line's first word that is no OBJ keyword nor could be an exporter's. */
static pd_status not_keyword(pd_text *t, pd_diag *diag, const char *s, size_t n)
{
    char shown[48];
    return pd_text_fail(t, diag, PD_ERR_PARSE, "expected an OBJ keyword, found %s",
                        pd_text_show(shown, sizeof shown, s, n));
}

pd_status pd_obj_check_head(const char *head, size_t n, const char *name, pd_diag *diag)
{
    pd_text t;
    pd_text_init(&t, head, n, name, '#', 1);
    const char *s;
    size_t len;
    if (!pd_text_next_line(&t) || !pd_text_token(&t, &s, &len) ||
        pd_obj_is_keyword(s, len) || looks_like_keyword(s, len))
        return PD_OK;
    return not_keyword(&t, diag, s, len);
}

pd_status pd_obj_read(const char *data, size_t size, const char *name, double scale,
                      pd_mesh **mesh, pd_diag *diag,
                      pd_cancel_flag *cancel)
{
    pd_text t;
    pd_text_init(&t, data, size, name, '#', 1);
    t.cancel = cancel;
    pd_build b = {0};
    pd_status st = PD_OK;
    while (st == PD_OK && pd_text_next_line(&t)) {
        const char *s;
        size_t n;
        pd_text_token(&t, &s, &n);
        if (n == 1 && s[0] == 'v')
            st = read_vertex(&t, diag, scale, &b);
        else if (n == 1 && s[0] == 'f')
            st = read_face(&t, diag, &b);
        else if (!is_ignored(s, n) && !looks_like_keyword(s, n))
            st = not_keyword(&t, diag, s, n);
    }
    if (st == PD_OK && b.ntris == 0)
        st = pd_fail(diag, PD_ERR_PARSE, "%s: no faces (OBJ without 'f' lines)", name);
    if (st == PD_OK && (st = pd_build_finish(&b, mesh)) != PD_OK)
        pd_fail(diag, st, "%s: out of memory", name);
    if (st != PD_OK)
        pd_build_free(&b);
    return st;
}
