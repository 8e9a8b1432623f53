/* mesh.c: units, reading a mesh file whole, telling its format, and the small
 * operations on a pd_mesh (clone, size, free). */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "mesh/mesh_internal.h"
#include "mesh/mesh_reader.h"
#include "posedrop/mesh.h"
#include "base/file_read.h"
#include "base/vec3.h"

double pd_units_scale(pd_units units)
{
    switch (units) {
    case PD_UNITS_CM:
        return 0.01;
    case PD_UNITS_MM:
        return 0.001;
    case PD_UNITS_IN:
        return 0.0254;
    case PD_UNITS_M:
        return 1.0;
    default:
        return 0.0;
    }
}

pd_status pd_units_parse(const char *text, pd_units *units)
{
    static const struct {
        const char *name;
        pd_units units;
    } table[] = {{"m", PD_UNITS_M}, {"cm", PD_UNITS_CM}, {"mm", PD_UNITS_MM}, {"in", PD_UNITS_IN}};
    if (!text || !units)
        return PD_ERR_USAGE;
    for (size_t i = 0; i < sizeof table / sizeof table[0]; i++)
        if (strcmp(text, table[i].name) == 0) {
            *units = table[i].units;
            return PD_OK;
        }
    return PD_ERR_USAGE;
}

/* A part dropped onto a feeder, a belt or a bin: from a grain of 0.5 mm (a
 * small SMD part, a watch screw) to 2 m across (a panel). A file in
 * millimetres read as metres is a thousand times too large, one in metres
 * read as millimetres a thousand times too small, so either lands well
 * outside this range for any part inside it. */
#define PLAUSIBLE_SIZE_MIN 0.5e-3 /* m, bounding-box diagonal */
#define PLAUSIBLE_SIZE_MAX 2.0    /* m */

static int plausible_size(double size)
{
    return size >= PLAUSIBLE_SIZE_MIN && size <= PLAUSIBLE_SIZE_MAX;
}

int pd_units_plausible(double size, pd_units units, pd_units *suggest)
{
    /* From the smallest unit to the largest: a part too large is suggested
     * the first smaller unit that makes it plausible (millimetres, the usual
     * CAD unit, first), one too small the first larger from the other end
     * (metres first). */
    static const pd_units order[] = {PD_UNITS_MM, PD_UNITS_CM, PD_UNITS_IN, PD_UNITS_M};
    enum { N = sizeof order / sizeof order[0] };
    if (suggest)
        *suggest = units;
    double scale = pd_units_scale(units);
    if (!(size == size) || scale == 0.0 || plausible_size(size))
        return 1;
    double file_size = size / scale; /* in the file's numbers */
    int large = size > PLAUSIBLE_SIZE_MAX;
    for (int i = 0; i < N; i++) {
        pd_units u = order[large ? i : N - 1 - i];
        if (u != units && plausible_size(file_size * pd_units_scale(u))) {
            if (suggest)
                *suggest = u;
            break;
        }
    }
    return 0;
}

void pd_mesh_read_options_default(pd_mesh_read_options *options)
{
    if (!options)
        return;
    options->format = PD_FORMAT_AUTO;
    options->units = PD_UNITS_M;
    options->cancel = NULL;
}

/* --- format detection ----------------------------------------------------- */

static pd_mesh_format by_extension(const char *name)
{
    const char *dot = strrchr(name, '.');
    if (!dot)
        return PD_FORMAT_AUTO;
    size_t n = strlen(dot + 1);
    if (pd_text_is(dot + 1, n, "off"))
        return PD_FORMAT_OFF;
    if (pd_text_is(dot + 1, n, "stl"))
        return PD_FORMAT_STL;
    if (pd_text_is(dot + 1, n, "obj"))
        return PD_FORMAT_OBJ;
    return PD_FORMAT_AUTO;
}

/* d holds the first n bytes of a file of size bytes (all of it, or the head
 * pd_mesh_read checks first). */
static pd_mesh_format by_content(const unsigned char *d, size_t n, size_t size)
{
    /* Binary STL has no magic number; its size formula is the signature. */
    if (n >= 84) {
        uint32_t count = (uint32_t)d[80] | (uint32_t)d[81] << 8 | (uint32_t)d[82] << 16 |
                         (uint32_t)d[83] << 24;
        if (84 + 50 * (uint64_t)count == size)
            return PD_FORMAT_STL;
    }
    /* The first word of the text, past '#' comments (which STL lacks, but its
     * first word "solid" is on a line without one). */
    pd_text t;
    pd_text_init(&t, d, n, "", '#', 0);
    const char *s;
    size_t len;
    if (pd_text_token_any(&t, &s, &len)) {
        if (pd_off_is_keyword(s, len))
            return PD_FORMAT_OFF;
        if (pd_stl_is_solid(s, len))
            return PD_FORMAT_STL;
        if (pd_obj_is_keyword(s, len))
            return PD_FORMAT_OBJ;
    }
    return PD_FORMAT_AUTO;
}

static pd_mesh_format detect(const unsigned char *d, size_t n, size_t size, const char *name)
{
    pd_mesh_format f = by_content(d, n, size);
    if (f == PD_FORMAT_AUTO)
        f = by_extension(name);
    /* Bytes no text format contains: the only binary format read is STL, so
     * a damaged one gets STL's message (a size that does not add up). */
    if (f == PD_FORMAT_AUTO && n > 0 && memchr(d, 0, n < 84 ? n : 84))
        f = PD_FORMAT_STL;
    return f;
}

static pd_status unknown_format(size_t size, const char *name, pd_diag *diag)
{
    if (size == 0)
        return pd_fail(diag, PD_ERR_FORMAT,
                       "%s: empty file of unknown format (name it .off, .stl or .obj)", name);
    return pd_fail(diag, PD_ERR_FORMAT,
                   "%s: unknown format: neither OFF, STL nor OBJ (use --format to say which)",
                   name);
}

/* The first n bytes of a file of size bytes: what each reader checks first,
 * refused here as the whole file's reading would refuse it. */
static pd_status check_head(const unsigned char *head, size_t n, size_t size, const char *name,
                            pd_mesh_format f, pd_diag *diag)
{
    if (f == PD_FORMAT_AUTO) {
        f = detect(head, n, size, name);
        /* Unknown by its first word: the rest cannot change that (unless
         * the head holds no word at all). */
        pd_text t;
        pd_text_init(&t, head, n, "", '#', 0);
        const char *s;
        size_t len;
        if (f == PD_FORMAT_AUTO && pd_text_token_any(&t, &s, &len))
            return unknown_format(size, name, diag);
    }
    switch (f) {
    case PD_FORMAT_OFF:
        return pd_off_check_head((const char *)head, n, name, diag);
    case PD_FORMAT_OBJ:
        return pd_obj_check_head((const char *)head, n, name, diag);
    case PD_FORMAT_STL:
        return pd_stl_check_head(head, n, size, name, diag);
    default:
        return PD_OK;
    }
}

/* --- reading ---------------------------------------------------------------- */

pd_status pd_mesh_parse(const void *data, size_t size, const char *name,
                        const pd_mesh_read_options *options, pd_mesh **mesh, pd_diag *diag)
{
    if (!mesh || (!data && size > 0))
        return pd_fail(diag, PD_ERR_USAGE, "pd_mesh_parse: NULL %s", mesh ? "data" : "mesh");
    pd_mesh_read_options defaults;
    if (!options) {
        pd_mesh_read_options_default(&defaults);
        options = &defaults;
    }
    if (!name)
        name = "<memory>";
    if ((unsigned)options->format > (unsigned)PD_FORMAT_OBJ)
        return pd_fail(diag, PD_ERR_USAGE, "%s: read option format is %d: expected one of "
                       "PD_FORMAT_AUTO, _OFF, _STL, _OBJ", name, (int)options->format);
    if ((unsigned)options->units > (unsigned)PD_UNITS_IN)
        return pd_fail(diag, PD_ERR_USAGE, "%s: read option units is %d: expected one of "
                       "PD_UNITS_M, _CM, _MM, _IN", name, (int)options->units);
    double scale = pd_units_scale(options->units);
    const unsigned char *d = data;
    pd_mesh_format f = options->format;
    if (f == PD_FORMAT_AUTO)
        f = detect(d, size, size, name);
    pd_status st;
    switch (f) {
    case PD_FORMAT_OFF:
        st = pd_off_read((const char *)d, size, name, scale, mesh, diag, options->cancel);
        break;
    case PD_FORMAT_STL:
        st = pd_stl_read(d, size, name, scale, mesh, diag, options->cancel);
        break;
    case PD_FORMAT_OBJ:
        st = pd_obj_read((const char *)d, size, name, scale, mesh, diag, options->cancel);
        break;
    case PD_FORMAT_AUTO:
    default:
        return unknown_format(size, name, diag);
    }
    /* A reader stopped by the cancel flag saw its input end early and may
     * have called that a parse error, or (the flag set after its last
     * line) finished: either way the caller asked to stop. */
    if (options->cancel && atomic_load(options->cancel)) {
        if (st == PD_OK) {
            pd_mesh_free(*mesh);
            *mesh = NULL;
        }
        return pd_fail(diag, PD_ERR_CANCELLED, "%s: reading cancelled", name);
    }
    return st;
}

/* The bytes read first from a regular file, before the rest: far more than
 * any reader's header or first keyword, and the window in which ASCII STL's
 * structure is looked for (16 KiB). */
#define HEAD_BYTES ((size_t)1 << 16)

/* Reads the whole file, up to max bytes; works for pipes too, which have no
 * size to ask for. A regular file larger than its head has its head checked
 * (check_head) before the rest is read. */
static pd_status slurp(int fd, const char *path, size_t max, pd_mesh_format format,
                       unsigned char **out, size_t *size, pd_diag *diag)
{
    struct stat sb;
    if (fstat(fd, &sb) != 0)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    if (S_ISDIR(sb.st_mode))
        return pd_fail(diag, PD_ERR_IO, "%s: is a directory, not a mesh file", path);
    int regular = S_ISREG(sb.st_mode);
    /* A regular file's size is known: refuse it before reading. */
    if (regular && (uintmax_t)sb.st_size > max)
        return pd_fail(diag, PD_ERR_RANGE, "%s: %jd bytes; posedrop reads mesh files of at "
                       "most %zu bytes", path, (intmax_t)sb.st_size, max);
    size_t cap = HEAD_BYTES, n = 0;
    int head_checked = !regular || (size_t)sb.st_size <= HEAD_BYTES;
    unsigned char *buf = malloc(cap);
    if (!buf)
        return pd_fail(diag, PD_ERR_NOMEM, "%s: out of memory", path);
    for (;;) {
        if (n == cap && !head_checked) {
            pd_status st = check_head(buf, n, (size_t)sb.st_size, path, format, diag);
            if (st != PD_OK) {
                free(buf);
                return st;
            }
            head_checked = 1;
        }
        if (n == cap) {
            if (n > max) {
                free(buf);
                return pd_fail(diag, PD_ERR_RANGE, "%s: more than %zu bytes and not at its end "
                               "(an endless input?); posedrop reads mesh files of at most %zu "
                               "bytes", path, max, max);
            }
            /* Up to one byte past the limit, which tells "too long" apart. */
            size_t next = cap <= max / 2 ? cap * 2 : max + 1;
            unsigned char *q = realloc(buf, next);
            if (!q) {
                free(buf);
                return pd_fail(diag, PD_ERR_NOMEM, "%s: out of memory after %zu bytes", path, n);
            }
            buf = q;
            cap = next;
        }
        ssize_t got = read(fd, buf + n, cap - n);
        if (got < 0 && errno == EINTR)
            continue;
        if (got < 0) {
            int err = errno;
            free(buf);
            return pd_fail(diag, PD_ERR_IO, "%s: cannot read: %s", path, strerror(err));
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    pd_status st = pd_file_check_fifo(fd, n, path, diag);
    if (st != PD_OK) {
        free(buf);
        return st;
    }
    *out = buf;
    *size = n;
    return PD_OK;
}

pd_status pd_mesh_read_capped(const char *path, const pd_mesh_read_options *options,
                              size_t max_bytes, pd_mesh **mesh, pd_diag *diag)
{
    if (!path || !mesh)
        return pd_fail(diag, PD_ERR_USAGE, "pd_mesh_read: NULL %s", path ? "mesh" : "path");
    int fd = pd_file_open_read(path);
    if (fd < 0)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char *data = NULL;
    size_t size = 0;
    pd_mesh_format format = options ? options->format : PD_FORMAT_AUTO;
    pd_status st = slurp(fd, path, max_bytes, format, &data, &size, diag);
    close(fd);
    if (st != PD_OK)
        return st;
    st = pd_mesh_parse(data, size, path, options, mesh, diag);
    free(data);
    return st;
}

pd_status pd_mesh_read(const char *path, const pd_mesh_read_options *options, pd_mesh **mesh,
                       pd_diag *diag)
{
    return pd_mesh_read_capped(path, options, PD_MESH_MAX_BYTES, mesh, diag);
}

/* --- the mesh itself -------------------------------------------------------- */

pd_mesh *pd_mesh_clone(const pd_mesh *mesh)
{
    if (!mesh || mesh->nverts < 0 || mesh->ntris < 0)
        return NULL;
    pd_mesh *c = malloc(sizeof *c);
    if (!c)
        return NULL;
    /* malloc(0) may return NULL; one spare element keeps NULL meaning failure. */
    c->verts = malloc(sizeof *c->verts * ((size_t)mesh->nverts + 1));
    c->tris = malloc(sizeof *c->tris * ((size_t)mesh->ntris + 1));
    if (!c->verts || !c->tris) {
        pd_mesh_free(c);
        return NULL;
    }
    c->nverts = mesh->nverts;
    c->ntris = mesh->ntris;
    if (mesh->nverts)
        memcpy(c->verts, mesh->verts, sizeof *c->verts * (size_t)mesh->nverts);
    if (mesh->ntris)
        memcpy(c->tris, mesh->tris, sizeof *c->tris * (size_t)mesh->ntris);
    return c;
}

double pd_mesh_size(const pd_mesh *mesh)
{
    if (!mesh || mesh->nverts <= 0 || !mesh->verts)
        return 0.0;
    pd_vec3 lo = mesh->verts[0], hi = lo;
    for (int i = 1; i < mesh->nverts; i++) {
        pd_vec3 v = mesh->verts[i];
        lo = v3_min(lo, v);
        hi = v3_max(hi, v);
    }
    return v3_dist(lo, hi);
}

void pd_mesh_free(pd_mesh *mesh)
{
    if (!mesh)
        return;
    free(mesh->verts);
    free(mesh->tris);
    free(mesh);
}

pd_status pd_mesh_validate(const pd_mesh *m, const char *who, pd_diag *diag)
{
    if (!m)
        return pd_fail(diag, PD_ERR_USAGE, "%s: mesh is NULL", who);
    if (m->nverts < 0 || m->ntris < 0 || (m->ntris > 0 && !m->tris) || (m->nverts > 0 && !m->verts))
        return pd_fail(diag, PD_ERR_USAGE, "%s: invalid mesh (%d vertices, %d triangles)", who,
                       m->nverts, m->ntris);
    for (int t = 0; t < m->ntris; t++)
        for (int c = 0; c < 3; c++)
            if (m->tris[t][c] < 0 || m->tris[t][c] >= m->nverts)
                return pd_fail(diag, PD_ERR_RANGE, "%s: triangle %d: vertex index %d out of range 0..%d",
                               who, t, m->tris[t][c], m->nverts - 1);
    for (int v = 0; v < m->nverts; v++)
        if (!v3_isfinite(m->verts[v]))
            return pd_fail(diag, PD_ERR_NONFINITE, "%s: vertex %d is not finite", who, v);
    return PD_OK;
}
