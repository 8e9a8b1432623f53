/* posedrop_module.c: the CPython extension posedrop._posedrop, a thin client
 * of libposedrop's public API (include/posedrop/).
 *
 * Arrays cross in both directions through the buffer protocol: the Python
 * layer (src/posedrop/) hands in C-contiguous float64 and int32 arrays and
 * wraps the bytearrays returned here with numpy.frombuffer, so the module
 * builds without numpy's headers and works with any numpy. Every library
 * call that may take long runs without the GIL; drops run on a worker thread
 * while the calling thread waits for them in short slices, so that Ctrl-C
 * (and a caller's cancel event) reach the library's cancel flag. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <posedrop/posedrop.h>

/* How often the thread waiting for drops looks at signals, the cancel
 * event and progress: short enough that Ctrl-C feels immediate, long
 * enough that taking the GIL costs nothing measurable. */
#define WAIT_SLICE_NS 50000000L

static PyObject *input_error, *internal_error, *posedrop_warning;

/* --- warnings and errors ---------------------------------------------- */

/* The library's warnings, gathered while the GIL is released (possibly from
 * its worker threads) and issued as Python warnings afterwards. */
typedef struct {
    pthread_mutex_t lock;
    char **msg;
    int n, cap;
} warn_box;

static void warn_collect(void *user, const char *message)
{
    warn_box *w = user;
    pthread_mutex_lock(&w->lock);
    if (w->n == w->cap) {
        int cap = w->cap ? 2 * w->cap : 8;
        char **grown = realloc(w->msg, sizeof *grown * (size_t)cap);
        if (grown) {
            w->msg = grown;
            w->cap = cap;
        }
    }
    if (w->n < w->cap && (w->msg[w->n] = strdup(message)) != NULL)
        w->n++;
    pthread_mutex_unlock(&w->lock);
}

static void diag_start(pd_diag *diag, warn_box *w)
{
    memset(w, 0, sizeof *w);
    pthread_mutex_init(&w->lock, NULL);
    pd_diag_init(diag);
    diag->warn = warn_collect;
    diag->warn_user = w;
}

/* Issues the gathered warnings and frees them; -1 if one became an error
 * (a warnings filter set to "error"). */
static int diag_finish(warn_box *w)
{
    int rc = 0;
    for (int i = 0; i < w->n; i++) {
        if (rc == 0 && PyErr_WarnEx(posedrop_warning, w->msg[i], 2) < 0)
            rc = -1;
        free(w->msg[i]);
    }
    free(w->msg);
    pthread_mutex_destroy(&w->lock);
    return rc;
}

/* Raises the library's status as posedrop.InputError or InternalError. */
static PyObject *raise_status(pd_status st, const char *message)
{
    int input = pd_status_is_input_error(st);
    PyObject *cls = input ? input_error : internal_error;
    PyObject *exc = PyObject_CallFunction(cls, "iss", (int)st, pd_status_str(st),
                                          message && *message ? message : pd_status_str(st));
    if (exc) {
        PyErr_SetObject(cls, exc);
        Py_DECREF(exc);
    }
    return NULL;
}

/* Frees the gathered warnings unissued: an exception is already set. */
static void diag_discard(warn_box *w)
{
    for (int i = 0; i < w->n; i++)
        free(w->msg[i]);
    free(w->msg);
    pthread_mutex_destroy(&w->lock);
}

static PyObject *fail(pd_status st, const pd_diag *diag, warn_box *w)
{
    /* The warnings first, as the command prints them before its error; one
     * that a filter turned into an exception must not hide the error. */
    if (diag_finish(w) < 0)
        PyErr_Clear();
    return raise_status(st, diag->message);
}

/* --- small helpers ----------------------------------------------------- */

/* A bytearray holding n items of size bytes, filled by the caller. */
static PyObject *new_buffer(size_t n, size_t size, void **data)
{
    PyObject *b = PyByteArray_FromStringAndSize(NULL, (Py_ssize_t)(n * size));
    if (b)
        *data = PyByteArray_AS_STRING(b);
    return b;
}

/* Adds key -> value to dict d and drops the reference to value; -1 when
 * value is NULL (an error set) or the insertion fails. */
static int put(PyObject *d, const char *key, PyObject *value)
{
    if (!value)
        return -1;
    int rc = PyDict_SetItemString(d, key, value);
    Py_DECREF(value);
    return rc;
}

static int put_doubles(PyObject *d, const char *key, const double *src, size_t n)
{
    void *data = NULL;
    PyObject *b = new_buffer(n, sizeof(double), &data);
    if (b && n)
        memcpy(data, src, n * sizeof(double));
    return put(d, key, b);
}

static int put_longs(PyObject *d, const char *key, const long *src, size_t n)
{
    void *data = NULL;
    PyObject *b = new_buffer(n, sizeof(int64_t), &data);
    for (size_t i = 0; b && i < n; i++)
        ((int64_t *)data)[i] = src[i];
    return put(d, key, b);
}

/* A name from a table of choices, or None for the default (*out unchanged). */
static int choose(const char *what, const char *const *names, PyObject *value, int *out)
{
    if (value == Py_None)
        return 0;
    const char *text = PyUnicode_Check(value) ? PyUnicode_AsUTF8(value) : NULL;
    for (int i = 0; text && names[i]; i++)
        if (strcmp(text, names[i]) == 0) {
            *out = i;
            return 0;
        }
    if (PyErr_Occurred())
        return -1;
    char msg[PD_DIAG_MESSAGE_LEN];
    int len = snprintf(msg, sizeof msg, "%s: expected", what);
    for (int i = 0; names[i] && len < (int)sizeof msg; i++)
        len += snprintf(msg + len, sizeof msg - (size_t)len, "%s '%s'",
                        i ? (names[i + 1] ? "," : " or") : "", names[i]);
    PyObject *repr = PyObject_Repr(value);
    const char *got = repr ? PyUnicode_AsUTF8(repr) : NULL;
    if (got && len < (int)sizeof msg)
        snprintf(msg + len, sizeof msg - (size_t)len, ", got %s", got);
    Py_XDECREF(repr);
    PyErr_Clear(); /* a value without a printable repr is still refused below */
    raise_status(PD_ERR_USAGE, msg);
    return -1;
}

/* A finite number; name is for the message. */
static int finite_double(const char *name, PyObject *value, double *out)
{
    double x = PyFloat_AsDouble(value);
    if (x == -1.0 && PyErr_Occurred())
        return -1;
    if (!isfinite(x)) {
        char msg[128];
        snprintf(msg, sizeof msg, "%s is %g: expected a finite number", name, x);
        raise_status(PD_ERR_NONFINITE, msg);
        return -1;
    }
    *out = x;
    return 0;
}

/* com: None or three finite numbers, times scale (the file's units, as the
 * command's --com). */
static int read_com(PyObject *com, double scale, pd_part_options *opt)
{
    if (com == Py_None)
        return 0;
    PyObject *seq = PySequence_Fast(com, "com must be a sequence of three numbers");
    if (!seq)
        return -1;
    int rc = -1;
    if (PySequence_Fast_GET_SIZE(seq) != 3) {
        raise_status(PD_ERR_USAGE, "com: expected three numbers X, Y, Z");
    } else {
        double c[3];
        static const char *const names[] = {"com[0]", "com[1]", "com[2]"};
        rc = 0;
        for (int i = 0; i < 3 && rc == 0; i++)
            rc = finite_double(names[i], PySequence_Fast_ITEMS(seq)[i], &c[i]);
        if (rc == 0) {
            opt->com_given = 1;
            opt->com = (pd_vec3){c[0] * scale, c[1] * scale, c[2] * scale};
        }
    }
    Py_DECREF(seq);
    return rc;
}

static int read_units(PyObject *units, pd_units *out)
{
    if (units == Py_None)
        return 0;
    const char *text = PyUnicode_Check(units) ? PyUnicode_AsUTF8(units) : NULL;
    if (text && pd_units_parse(text, out) == PD_OK)
        return 0;
    if (!PyErr_Occurred())
        raise_status(PD_ERR_USAGE, "units: expected 'm', 'cm', 'mm' or 'in'");
    return -1;
}

/* --- Part ------------------------------------------------------------- */

typedef struct {
    PyObject_HEAD
    pd_part *part;
} PartObject;

static PyTypeObject PartType;

static void Part_dealloc(PartObject *self)
{
    pd_part_free(self->part);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *part_new(pd_part *part)
{
    PartObject *p = PyObject_New(PartObject, &PartType);
    if (!p) {
        pd_part_free(part);
        return NULL;
    }
    p->part = part;
    return (PyObject *)p;
}

/* Builds the part without the GIL and wraps it. */
static PyObject *build_part(const pd_mesh *mesh, const pd_part_options *opt)
{
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    pd_part *part = NULL;
    pd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = pd_part_build(mesh, opt, &part, &diag);
    Py_END_ALLOW_THREADS
    if (st != PD_OK)
        return fail(st, &diag, &w);
    if (diag_finish(&w) < 0) {
        pd_part_free(part);
        return NULL;
    }
    return part_new(part);
}

static const char *const format_names[] = {"auto", "off", "stl", "obj", NULL};

static PyObject *part_from_file(PyObject *mod, PyObject *args, PyObject *kw)
{
    (void)mod;
    static char *kwlist[] = {"path", "units", "format", "com", NULL};
    PyObject *path = NULL, *units = Py_None, *format = Py_None, *com = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O&|OOO", kwlist, PyUnicode_FSConverter, &path,
                                     &units, &format, &com))
        return NULL;
    pd_mesh_read_options ropt;
    pd_mesh_read_options_default(&ropt);
    pd_part_options popt;
    pd_part_options_default(&popt);
    int fmt = 0;
    if (read_units(units, &ropt.units) < 0 || choose("format", format_names, format, &fmt) < 0 ||
        read_com(com, pd_units_scale(ropt.units), &popt) < 0) {
        Py_DECREF(path);
        return NULL;
    }
    ropt.format = (pd_mesh_format)fmt;
    const char *cpath = PyBytes_AS_STRING(path);
    if (strlen(cpath) != (size_t)PyBytes_GET_SIZE(path)) {
        Py_DECREF(path);
        return raise_status(PD_ERR_USAGE, "path: a file name holds no NUL character");
    }
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    pd_mesh *mesh = NULL;
    pd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = pd_mesh_read(cpath, &ropt, &mesh, &diag);
    Py_END_ALLOW_THREADS
    Py_DECREF(path);
    if (st != PD_OK)
        return fail(st, &diag, &w);
    if (diag_finish(&w) < 0) {
        pd_mesh_free(mesh);
        return NULL;
    }
    PyObject *part = build_part(mesh, &popt);
    pd_mesh_free(mesh);
    return part;
}

/* A C-contiguous 2-D buffer of rows of 3 items of the given struct format. */
static int get_rows(PyObject *obj, const char *name, char format, Py_ssize_t itemsize,
                    Py_buffer *view)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    if (view->ndim != 2 || view->shape[1] != 3 || view->itemsize != itemsize || f[0] != format ||
        f[1] != '\0') {
        PyBuffer_Release(view);
        PyErr_Format(PyExc_ValueError, "%s: expected a C-contiguous (n, 3) array of '%c'", name,
                     format);
        return -1;
    }
    return 0;
}

static PyObject *part_from_arrays(PyObject *mod, PyObject *args, PyObject *kw)
{
    (void)mod;
    static char *kwlist[] = {"vertices", "faces", "com", "units", NULL};
    PyObject *vobj, *fobj, *com = Py_None, *units = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|OO", kwlist, &vobj, &fobj, &com, &units))
        return NULL;
    pd_units u = PD_UNITS_M;
    pd_part_options popt;
    pd_part_options_default(&popt);
    if (read_units(units, &u) < 0 || read_com(com, pd_units_scale(u), &popt) < 0)
        return NULL;
    Py_buffer vb, fb;
    if (get_rows(vobj, "vertices", 'd', sizeof(double), &vb) < 0)
        return NULL;
    if (get_rows(fobj, "faces", 'i', sizeof(int), &fb) < 0) {
        PyBuffer_Release(&vb);
        return NULL;
    }
    PyObject *result = NULL;
    char msg[PD_DIAG_MESSAGE_LEN] = "";
    pd_status st = PD_OK;
    Py_ssize_t nv = vb.shape[0], nt = fb.shape[0];
    pd_mesh mesh = {0, NULL, 0, NULL};
    if (nv > INT_MAX / 3 || nt > INT_MAX / 3) {
        st = PD_ERR_RANGE;
        snprintf(msg, sizeof msg, "%zd vertices and %zd faces: more than a mesh may hold", nv, nt);
        goto done;
    }
    mesh.nverts = (int)nv;
    mesh.ntris = (int)nt;
    mesh.verts = malloc(sizeof *mesh.verts * (size_t)(nv ? nv : 1));
    mesh.tris = malloc(sizeof *mesh.tris * (size_t)(nt ? nt : 1));
    if (!mesh.verts || !mesh.tris) {
        PyErr_NoMemory();
        goto done;
    }
    /* What the file readers check, so that any array the library receives is
     * a mesh it could have read: finite coordinates, indices in range. */
    double scale = pd_units_scale(u);
    const double *v = vb.buf;
    for (Py_ssize_t i = 0; i < nv && st == PD_OK; i++) {
        for (int k = 0; k < 3; k++)
            if (!isfinite(v[3 * i + k])) {
                st = PD_ERR_NONFINITE;
                snprintf(msg, sizeof msg, "vertices[%zd, %d] is %g: expected a finite number", i,
                         k, v[3 * i + k]);
                break;
            }
        mesh.verts[i] = (pd_vec3){v[3 * i] * scale, v[3 * i + 1] * scale, v[3 * i + 2] * scale};
    }
    const int *f = fb.buf;
    for (Py_ssize_t i = 0; i < nt && st == PD_OK; i++)
        for (int k = 0; k < 3; k++) {
            int idx = f[3 * i + k];
            if (idx < 0 || idx >= mesh.nverts) {
                st = PD_ERR_RANGE;
                snprintf(msg, sizeof msg, "faces[%zd, %d] is %d: expected a vertex index from 0 "
                         "to %d", i, k, idx, mesh.nverts - 1);
                break;
            }
            mesh.tris[i][k] = idx;
        }
    if (st == PD_OK)
        result = build_part(&mesh, &popt);
done:
    PyBuffer_Release(&vb);
    PyBuffer_Release(&fb);
    free(mesh.verts);
    free(mesh.tris);
    if (st != PD_OK)
        return raise_status(st, msg);
    return result;
}

static PyObject *vec3(pd_vec3 v)
{
    return Py_BuildValue("(ddd)", v.x, v.y, v.z);
}

static PyObject *Part_info(PartObject *self, PyObject *unused)
{
    (void)unused;
    const pd_part *p = self->part;
    const pd_vec3 o = p->origin;
    PyObject *d = PyDict_New();
    if (!d)
        return NULL;
    const double *I = &p->mass.inertia[0][0];
    int bad = put(d, "size", PyFloat_FromDouble(p->size)) ||
              put(d, "closed", PyBool_FromLong(p->closed)) ||
              put(d, "com", vec3((pd_vec3){p->com.x + o.x, p->com.y + o.y, p->com.z + o.z})) ||
              put(d, "origin", vec3(o)) ||
              put(d, "nverts", PyLong_FromLong(p->mesh->nverts)) ||
              put(d, "ntris", PyLong_FromLong(p->mesh->ntris)) ||
              put(d, "hull_nverts", PyLong_FromLong(p->hull->nverts)) ||
              put(d, "hull_nfacets", PyLong_FromLong(p->hull->nfacets)) ||
              put(d, "hull_volume", PyFloat_FromDouble(p->hull->volume));
    if (!bad && p->mass_known)
        bad = put(d, "volume", PyFloat_FromDouble(p->mass.volume)) ||
              put(d, "mass_com", vec3((pd_vec3){p->mass.com.x + o.x, p->mass.com.y + o.y,
                                                p->mass.com.z + o.z})) ||
              put_doubles(d, "inertia", I, 9);
    if (bad) {
        Py_DECREF(d);
        return NULL;
    }
    return d;
}

/* Vertices moved back to the mesh's frame (the part keeps them relative to
 * its origin). */
static PyObject *points_buffer(const pd_vec3 *pts, int n, pd_vec3 o)
{
    void *data = NULL;
    PyObject *b = new_buffer((size_t)n * 3, sizeof(double), &data);
    for (int i = 0; b && i < n; i++) {
        double *r = (double *)data + 3 * i;
        r[0] = pts[i].x + o.x;
        r[1] = pts[i].y + o.y;
        r[2] = pts[i].z + o.z;
    }
    return b;
}

static PyObject *ints_buffer(const int *src, size_t n)
{
    void *data = NULL;
    PyObject *b = new_buffer(n, sizeof(int32_t), &data);
    for (size_t i = 0; b && i < n; i++)
        ((int32_t *)data)[i] = src[i];
    return b;
}

static PyObject *Part_mesh(PartObject *self, PyObject *unused)
{
    (void)unused;
    const pd_mesh *m = self->part->mesh;
    PyObject *v = points_buffer(m->verts, m->nverts, self->part->origin);
    PyObject *t = v ? ints_buffer(&m->tris[0][0], (size_t)m->ntris * 3) : NULL;
    if (!t) {
        Py_XDECREF(v);
        return NULL;
    }
    return Py_BuildValue("(NN)", v, t);
}

static PyObject *Part_hull(PartObject *self, PyObject *unused)
{
    (void)unused;
    const pd_hull *h = self->part->hull;
    PyObject *d = PyDict_New();
    if (!d)
        return NULL;
    int bad = put(d, "vertices", points_buffer(h->verts, h->nverts, self->part->origin)) ||
              put_doubles(d, "normal", &h->normal[0].x, (size_t)h->nfacets * 3) ||
              put(d, "facet_start", ints_buffer(h->facet_start, (size_t)h->nfacets + 1)) ||
              put(d, "facet_vert", ints_buffer(h->facet_vert, (size_t)h->facet_start[h->nfacets]));
    if (bad) {
        Py_DECREF(d);
        return NULL;
    }
    return d;
}

/* --- static estimate --------------------------------------------------- */

typedef struct {
    PyObject_HEAD
    PartObject *part;
    pd_static_result *res;
} PosesObject;

static PyTypeObject PosesType;

static void Poses_dealloc(PosesObject *self)
{
    pd_static_result_free(self->res);
    Py_XDECREF(self->part);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static const char *const topple_names[] = {"descent", "edge", NULL};
static const char *const compare_names[] = {"raw", "qs", NULL};
static const char *const band_names[] = {"rect", "exact", NULL};

static PyObject *Part_estimate(PartObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"topple", "epsilon", "pqs_compare", "pqs_band", NULL};
    PyObject *topple = Py_None, *epsilon = Py_None, *compare = Py_None, *band = Py_None;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "|OOOO", kwlist, &topple, &epsilon, &compare,
                                     &band))
        return NULL;
    pd_static_options opt;
    pd_static_options_default(&opt);
    int t = (int)opt.topple, c = (int)opt.compare, b = (int)opt.band;
    if (choose("topple", topple_names, topple, &t) < 0 ||
        choose("pqs_compare", compare_names, compare, &c) < 0 ||
        choose("pqs_band", band_names, band, &b) < 0)
        return NULL;
    opt.topple = (pd_topple_rule)t;
    opt.compare = (pd_pqs_compare)c;
    opt.band = (pd_pqs_band)b;
    if (epsilon != Py_None) {
        /* Degrees, converted as the command converts --epsilon. */
        double deg;
        if (finite_double("epsilon", epsilon, &deg) < 0)
            return NULL;
        opt.epsilon = deg * (M_PI / 180.0);
    }
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    pd_static_result *res = NULL;
    pd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = pd_static_estimate(self->part, &opt, &res, &diag);
    Py_END_ALLOW_THREADS
    if (st != PD_OK)
        return fail(st, &diag, &w);
    if (diag_finish(&w) < 0) {
        pd_static_result_free(res);
        return NULL;
    }
    PosesObject *p = PyObject_New(PosesObject, &PosesType);
    if (!p) {
        pd_static_result_free(res);
        return NULL;
    }
    Py_INCREF(self);
    p->part = self;
    p->res = res;
    return (PyObject *)p;
}

static PyObject *Poses_poses(PosesObject *self, PyObject *unused)
{
    (void)unused;
    const pd_static_result *r = self->res;
    size_t k = (size_t)r->nposes;
    PyObject *d = PyDict_New();
    if (!d)
        return NULL;
    void *facet = NULL, *normal = NULL, *area = NULL, *height = NULL, *qs = NULL, *pqs = NULL,
         *tf = NULL;
    int bad = put(d, "facet", new_buffer(k, sizeof(int32_t), &facet)) ||
              put(d, "normal", new_buffer(3 * k, sizeof(double), &normal)) ||
              put(d, "area", new_buffer(k, sizeof(double), &area)) ||
              put(d, "height", new_buffer(k, sizeof(double), &height)) ||
              put(d, "p_qs", new_buffer(k, sizeof(double), &qs)) ||
              put(d, "p_pqs", new_buffer(k, sizeof(double), &pqs)) ||
              put(d, "transform", new_buffer(16 * k, sizeof(double), &tf)) ||
              put(d, "nknife", PyLong_FromLong(r->nknife));
    if (bad) {
        Py_DECREF(d);
        return NULL;
    }
    for (size_t i = 0; i < k; i++) {
        const pd_pose *p = &r->poses[i];
        ((int32_t *)facet)[i] = p->facet;
        ((double *)normal)[3 * i] = p->normal.x;
        ((double *)normal)[3 * i + 1] = p->normal.y;
        ((double *)normal)[3 * i + 2] = p->normal.z;
        ((double *)area)[i] = p->area;
        ((double *)height)[i] = p->height;
        ((double *)qs)[i] = p->p_qs;
        ((double *)pqs)[i] = p->p_pqs;
        pd_diag diag;
        pd_diag_init(&diag);
        pd_status st = pd_pose_transform(self->part->part, p, (double *)tf + 16 * i, &diag);
        if (st != PD_OK) {
            Py_DECREF(d);
            return raise_status(st, diag.message);
        }
    }
    return d;
}

static PyObject *Poses_facets(PosesObject *self, PyObject *unused)
{
    (void)unused;
    const pd_static_result *r = self->res;
    size_t n = (size_t)r->nfacets;
    PyObject *d = PyDict_New();
    if (!d)
        return NULL;
    void *sa = NULL, *praw = NULL, *area = NULL, *height = NULL, *qs = NULL, *pqs = NULL;
    void *stable = NULL, *knife = NULL, *next = NULL, *rest = NULL, *pose = NULL;
    int bad = put(d, "solid_angle", new_buffer(n, sizeof(double), &sa)) ||
              put(d, "p_raw", new_buffer(n, sizeof(double), &praw)) ||
              put(d, "area", new_buffer(n, sizeof(double), &area)) ||
              put(d, "height", new_buffer(n, sizeof(double), &height)) ||
              put(d, "p_qs", new_buffer(n, sizeof(double), &qs)) ||
              put(d, "p_pqs", new_buffer(n, sizeof(double), &pqs)) ||
              put(d, "stable", new_buffer(n, sizeof(int32_t), &stable)) ||
              put(d, "knife", new_buffer(n, sizeof(int32_t), &knife)) ||
              put(d, "next", new_buffer(n, sizeof(int32_t), &next)) ||
              put(d, "rest", new_buffer(n, sizeof(int32_t), &rest)) ||
              put(d, "pose", new_buffer(n, sizeof(int32_t), &pose)) ||
              put_doubles(d, "normal", &self->part->part->hull->normal[0].x, 3 * n);
    if (bad) {
        Py_DECREF(d);
        return NULL;
    }
    for (size_t f = 0; f < n; f++) {
        const pd_facet_result *x = &r->facets[f];
        ((double *)sa)[f] = x->solid_angle;
        ((double *)praw)[f] = x->p_raw;
        ((double *)area)[f] = x->area;
        ((double *)height)[f] = x->height;
        ((double *)qs)[f] = x->p_qs;
        ((double *)pqs)[f] = x->p_pqs;
        ((int32_t *)stable)[f] = x->stable;
        ((int32_t *)knife)[f] = x->knife;
        ((int32_t *)next)[f] = x->next;
        ((int32_t *)rest)[f] = x->rest;
        ((int32_t *)pose)[f] = -1;
    }
    /* A stable facet's pose first, then every facet's through its rest. */
    for (int i = 0; i < r->nposes; i++)
        ((int32_t *)pose)[r->poses[i].facet] = i;
    for (size_t f = 0; f < n; f++)
        ((int32_t *)pose)[f] = ((int32_t *)pose)[r->facets[f].rest];
    return d;
}

static PyObject *Poses_classes(PosesObject *self, PyObject *unused)
{
    (void)unused;
    void *data = NULL;
    PyObject *b = new_buffer((size_t)self->res->nposes + 1, sizeof(int32_t), &data);
    if (!b)
        return NULL;
    int *class_of = malloc(sizeof *class_of * ((size_t)self->res->nposes + 1));
    if (!class_of) {
        Py_DECREF(b);
        return PyErr_NoMemory();
    }
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    int nclasses = 0;
    pd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = pd_pose_classes(self->part->part, self->res, class_of, &nclasses, &diag);
    Py_END_ALLOW_THREADS
    for (int i = 0; st == PD_OK && i < self->res->nposes; i++)
        ((int32_t *)data)[i] = class_of[i];
    free(class_of);
    if (st != PD_OK) {
        Py_DECREF(b);
        return fail(st, &diag, &w);
    }
    if (diag_finish(&w) < 0 || PyByteArray_Resize(b, (Py_ssize_t)(sizeof(int32_t) *
                                                                    (size_t)self->res->nposes)) < 0) {
        Py_DECREF(b);
        return NULL;
    }
    return Py_BuildValue("(Ni)", b, nclasses);
}

/* --- drops ------------------------------------------------------------- */

typedef struct {
    PyObject_HEAD
    pd_sim_result *sim;
    pd_scene scene;     /* the scene the drops ran in, for their sensitivity */
    double part_size;   /* pd_contact_time_auto_size of the part */
} DropsObject;

static PyTypeObject DropsType;

static void Drops_dealloc(DropsObject *self)
{
    pd_sim_result_free(self->sim);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *drops_new(pd_sim_result *sim, const pd_scene *scene, double part_size)
{
    DropsObject *d = PyObject_New(DropsObject, &DropsType);
    if (!d) {
        pd_sim_result_free(sim);
        return NULL;
    }
    d->sim = sim;
    d->scene = *scene;
    d->part_size = part_size;
    return (PyObject *)d;
}

/* One run of pd_sim_run on a worker thread. */
typedef struct {
    const pd_part *part;
    const pd_static_result *res;
    pd_scene scene;
    pd_sim_options options;
    pd_cancel_flag cancel;
    atomic_long done, total;
    pd_sim_result *sim;
    pd_diag diag;
    pd_status st;
    pthread_mutex_t lock;
    pthread_cond_t finished_cv;
    int finished;
} run_ctx;

static void on_progress(void *user, long done, long total)
{
    run_ctx *c = user;
    atomic_store(&c->done, done);
    atomic_store(&c->total, total);
}

static void *run_worker(void *arg)
{
    run_ctx *c = arg;
    c->st = pd_sim_run(c->part, c->res, &c->scene, &c->options, &c->sim, &c->diag);
    pthread_mutex_lock(&c->lock);
    c->finished = 1;
    pthread_cond_signal(&c->finished_cv);
    pthread_mutex_unlock(&c->lock);
    return NULL;
}

/* Waits up to one slice for the worker; 1 once it has finished. Called
 * without the GIL. */
static int wait_slice(run_ctx *c)
{
    struct timespec until;
    clock_gettime(CLOCK_MONOTONIC, &until);
    until.tv_nsec += WAIT_SLICE_NS;
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&c->lock);
    while (!c->finished && pthread_cond_timedwait(&c->finished_cv, &c->lock, &until) != ETIMEDOUT)
        ;
    int finished = c->finished;
    pthread_mutex_unlock(&c->lock);
    return finished;
}

/* The caller's cancel event: 1 if set, 0 if not, -1 on an error. */
static int cancel_requested(PyObject *event)
{
    if (event == Py_None)
        return 0;
    PyObject *r = PyObject_CallMethod(event, "is_set", NULL);
    if (!r)
        return -1;
    int set = PyObject_IsTrue(r);
    Py_DECREF(r);
    return set;
}

/* Runs the drops and waits for them with the GIL released in slices. On
 * Ctrl-C (or another exception from a signal handler, the cancel event or
 * the progress callback) the library's cancel flag is set, the drops under
 * way finish, the partial result is dropped and the exception propagates;
 * a set cancel event instead returns the partial result. */
static int run_and_wait(run_ctx *c, PyObject *event, PyObject *progress)
{
    pthread_condattr_t attr;
    pthread_condattr_init(&attr);
    pthread_condattr_setclock(&attr, CLOCK_MONOTONIC);
    pthread_cond_init(&c->finished_cv, &attr);
    pthread_condattr_destroy(&attr);
    pthread_mutex_init(&c->lock, NULL);
    pthread_t thread;
    int rc = pthread_create(&thread, NULL, run_worker, c);
    if (rc != 0) {
        errno = rc;
        PyErr_SetFromErrno(PyExc_OSError);
        pthread_cond_destroy(&c->finished_cv);
        pthread_mutex_destroy(&c->lock);
        return -1;
    }
    int failed = 0, finished = 0;
    long reported = -1;
    while (!finished) {
        Py_BEGIN_ALLOW_THREADS
        finished = wait_slice(c);
        Py_END_ALLOW_THREADS
        if (finished)
            break;
        int set = PyErr_CheckSignals() < 0 ? -1 : cancel_requested(event);
        if (set == 0 && progress != Py_None && atomic_load(&c->done) != reported) {
            reported = atomic_load(&c->done);
            PyObject *r = PyObject_CallFunction(progress, "ll", reported, atomic_load(&c->total));
            set = r ? 0 : -1;
            Py_XDECREF(r);
        }
        if (set != 0) {
            atomic_store(&c->cancel, 1);
            if (set < 0) {
                failed = 1;
                break;
            }
        }
    }
    Py_BEGIN_ALLOW_THREADS
    pthread_join(thread, NULL);
    Py_END_ALLOW_THREADS
    pthread_cond_destroy(&c->finished_cv);
    pthread_mutex_destroy(&c->lock);
    return failed ? -1 : 0;
}

static const char *const engine_names[] = {"impulse", "ode", "bullet", NULL};

/* Sets option *field from value unless it is None. */
static int opt_long(PyObject *value, long *field)
{
    if (value == Py_None)
        return 0;
    long x = PyLong_AsLong(value);
    if (x == -1 && PyErr_Occurred())
        return -1;
    *field = x;
    return 0;
}

static int opt_int(PyObject *value, int *field)
{
    long x = *field;
    if (opt_long(value, &x) < 0)
        return -1;
    if (x < INT_MIN || x > INT_MAX) {
        PyErr_SetString(PyExc_OverflowError, "value out of range of a C int");
        return -1;
    }
    *field = (int)x;
    return 0;
}

static int opt_double(const char *name, PyObject *value, double *field)
{
    return value == Py_None ? 0 : finite_double(name, value, field);
}

/* time_limit: None or "auto" keeps PD_TIME_LIMIT_AUTO; a number must be
 * above 0, as the command's --time-limit (0 would silently mean auto). */
static int opt_time_limit(PyObject *value, double *field)
{
    if (value == Py_None)
        return 0;
    if (PyUnicode_Check(value)) {
        if (PyUnicode_CompareWithASCIIString(value, "auto") == 0) {
            *field = PD_TIME_LIMIT_AUTO;
            return 0;
        }
        raise_status(PD_ERR_USAGE, "time_limit: expected a number of seconds or \"auto\"");
        return -1;
    }
    double x;
    if (finite_double("time_limit", value, &x) < 0)
        return -1;
    if (!(x > 0)) {
        char msg[PD_DIAG_MESSAGE_LEN];
        snprintf(msg, sizeof msg, "time_limit: expected seconds above 0 or \"auto\", got %g", x);
        raise_status(PD_ERR_RANGE, msg);
        return -1;
    }
    *field = x;
    return 0;
}

/* The scene: the defaults, then the file, then each (key, text) pair, all
 * through the library's own reader, as the command's --scene and options. */
static int build_scene(PyObject *file, PyObject *items, pd_scene *scene)
{
    pd_scene_default(scene);
    pd_diag diag;
    pd_diag_init(&diag);
    pd_status st = PD_OK;
    if (file != Py_None) {
        PyObject *path = NULL;
        if (!PyUnicode_FSConverter(file, &path))
            return -1;
        st = pd_scene_read(PyBytes_AS_STRING(path), scene, &diag);
        Py_DECREF(path);
        if (st != PD_OK) {
            raise_status(st, diag.message);
            return -1;
        }
    }
    PyObject *seq = PySequence_Fast(items, "scene settings must be a sequence of (key, value)");
    if (!seq)
        return -1;
    for (Py_ssize_t i = 0; i < PySequence_Fast_GET_SIZE(seq) && st == PD_OK; i++) {
        const char *key, *value;
        if (!PyArg_ParseTuple(PySequence_Fast_ITEMS(seq)[i], "ss", &key, &value)) {
            Py_DECREF(seq);
            return -1;
        }
        st = pd_scene_set(scene, key, value, &diag);
    }
    Py_DECREF(seq);
    if (st != PD_OK) {
        raise_status(st, diag.message);
        return -1;
    }
    return 0;
}

static PyObject *Poses_drop(PosesObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"scene_file", "scene", "n", "ci", "seed", "threads", "engine", "dt",
                             "max_drops", "time_limit", "max_collisions", "trials", "cancel",
                             "progress", NULL};
    PyObject *file = Py_None, *items = NULL, *n = Py_None, *ci = Py_None, *seed = Py_None;
    PyObject *threads = Py_None, *engine = Py_None, *dt = Py_None, *max_drops = Py_None;
    PyObject *time_limit = Py_None, *max_collisions = Py_None, *event = Py_None;
    PyObject *progress = Py_None;
    int trials = 0;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OO|OOOOOOOOOpOO", kwlist, &file, &items, &n, &ci,
                                     &seed, &threads, &engine, &dt, &max_drops, &time_limit,
                                     &max_collisions, &trials, &event, &progress))
        return NULL;
    if (progress != Py_None && !PyCallable_Check(progress)) {
        PyErr_SetString(PyExc_TypeError, "progress must be callable");
        return NULL;
    }
    run_ctx *c = calloc(1, sizeof *c);
    if (!c)
        return PyErr_NoMemory();
    c->part = self->part->part;
    c->res = self->res;
    pd_sim_options *o = &c->options;
    pd_sim_options_default(o);
    int eng = (int)o->engine;
    if (build_scene(file, items, &c->scene) < 0 || opt_long(n, &o->ndrops) < 0 ||
        opt_double("ci", ci, &o->ci_halfwidth) < 0 || opt_int(threads, &o->threads) < 0 ||
        choose("engine", engine_names, engine, &eng) < 0 || opt_double("dt", dt, &o->dt) < 0 ||
        opt_long(max_drops, &o->max_drops) < 0 ||
        opt_time_limit(time_limit, &o->time_limit) < 0 ||
        opt_int(max_collisions, &o->max_collisions) < 0) {
        free(c);
        return NULL;
    }
    if (seed != Py_None) {
        unsigned long long s = PyLong_AsUnsignedLongLong(seed);
        if (s == (unsigned long long)-1 && PyErr_Occurred()) {
            free(c);
            return NULL;
        }
        o->seed = (uint64_t)s;
    }
    o->engine = (pd_engine_kind)eng;
    o->keep_trials = trials;
    o->cancel = &c->cancel;
    o->progress = on_progress;
    o->progress_user = c;
    atomic_init(&c->cancel, 0);
    atomic_init(&c->done, 0);
    atomic_init(&c->total, o->ndrops);
    warn_box w;
    diag_start(&c->diag, &w);
    PyObject *result = NULL;
    if (run_and_wait(c, event, progress) < 0) {
        pd_sim_result_free(c->sim);
        diag_discard(&w);
    } else if (c->st != PD_OK) {
        fail(c->st, &c->diag, &w);
    } else if (diag_finish(&w) < 0) {
        pd_sim_result_free(c->sim);
    } else {
        result = drops_new(c->sim, &c->scene, pd_contact_time_auto_size(c->part));
    }
    free(c);
    return result;
}

static PyObject *Drops_arrays(DropsObject *self, PyObject *unused)
{
    (void)unused;
    const pd_sim_result *s = self->sim;
    size_t k = (size_t)s->nposes;
    PyObject *d = PyDict_New();
    if (!d)
        return NULL;
    int bad = put(d, "nposes", PyLong_FromLong(s->nposes)) ||
              put(d, "n", PyLong_FromLong(s->n)) || put_longs(d, "count", s->count, k) ||
              put_doubles(d, "p", s->p, k) || put_doubles(d, "ci_lo", s->ci_lo, k) ||
              put_doubles(d, "ci_hi", s->ci_hi, k) ||
              put(d, "unsettled", PyLong_FromLong(s->unsettled)) ||
              put(d, "time_limited", PyLong_FromLong(s->time_limited)) ||
              put(d, "collision_limited", PyLong_FromLong(s->collision_limited)) ||
              put(d, "failed", PyLong_FromLong(s->failed)) ||
              put(d, "first_failed", PyLong_FromLong(s->first_failed)) ||
              put(d, "failed_stage", PyLong_FromLong((long)s->failed_stage)) ||
              put(d, "failed_status", PyLong_FromLong((long)s->failed_status)) ||
              put(d, "time_limit", PyFloat_FromDouble(s->time_limit)) ||
              put(d, "energy_gain", PyLong_FromLong(s->energy_gain)) ||
              put(d, "fallbacks", PyLong_FromLong(s->fallbacks)) ||
              put(d, "collisions", PyLong_FromLong(s->collisions)) ||
              put(d, "partial", PyBool_FromLong(s->partial)) ||
              put(d, "bootstrap_rounds", PyLong_FromLong(s->bootstrap_rounds)) ||
              put(d, "stationarity", PyFloat_FromDouble(s->stationarity)) ||
              put(d, "seed", PyLong_FromUnsignedLongLong(s->seed));
    if (!bad && s->transitions)
        bad = put(d, "first_drops", PyLong_FromLong(s->first_drops)) ||
              put(d, "pose_drops", PyLong_FromLong(s->pose_drops)) ||
              put_longs(d, "first_count", s->first_count, k) ||
              put_longs(d, "transitions", s->transitions, k * k) ||
              put(d, "closed_classes", PyLong_FromLong(s->closed_classes)) ||
              put(d, "stationary_shift", PyFloat_FromDouble(s->stationary_shift));
    if (!bad && s->trials) {
        size_t m = (size_t)s->n;
        void *q0 = NULL, *pose = NULL, *coll = NULL, *time = NULL, *end = NULL;
        void *stage = NULL, *status = NULL, *param = NULL;
        bad = put(d, "trial_q0", new_buffer(4 * m, sizeof(double), &q0)) ||
              put(d, "trial_pose", new_buffer(m, sizeof(int32_t), &pose)) ||
              put(d, "trial_collisions", new_buffer(m, sizeof(int32_t), &coll)) ||
              put(d, "trial_time", new_buffer(m, sizeof(double), &time)) ||
              put(d, "trial_end", new_buffer(m, sizeof(int32_t), &end)) ||
              put(d, "trial_stage", new_buffer(m, sizeof(int32_t), &stage)) ||
              put(d, "trial_status", new_buffer(m, sizeof(int32_t), &status)) ||
              put(d, "trial_param", new_buffer(PD_NPARAMS * m, sizeof(double), &param));
        for (size_t i = 0; !bad && i < m; i++) {
            const pd_trial *t = &s->trials[i];
            memcpy((double *)q0 + 4 * i, t->q0, sizeof t->q0);
            memcpy((double *)param + PD_NPARAMS * i, t->param, sizeof t->param);
            ((int32_t *)pose)[i] = t->pose;
            ((int32_t *)coll)[i] = t->collisions;
            ((double *)time)[i] = t->time;
            ((int32_t *)end)[i] = (int32_t)t->end;
            ((int32_t *)stage)[i] = (int32_t)t->stage;
            ((int32_t *)status)[i] = (int32_t)t->status;
        }
    }
    /* The ranged parameters in pd_scene_param order: the drawn values'
     * columns, as --trials writes them. */
    PyObject *ranged = bad ? NULL : PyList_New(0);
    bad = bad || put(d, "ranged", ranged);
    for (int k = 0; !bad && k < PD_NPARAMS; k++)
        if (self->scene.range[k].kind != PD_DIST_FIXED) {
            PyObject *name = PyUnicode_FromString(pd_scene_param_name((pd_scene_param)k));
            bad = !name || PyList_Append(ranged, name) < 0;
            Py_XDECREF(name);
        }
    if (bad) {
        Py_DECREF(d);
        return NULL;
    }
    return d;
}

/* The class of each pose from a C-contiguous int32 buffer: 0 with the view
 * held (the caller releases it), -1 with an exception set. */
static int read_classes(const DropsObject *self, PyObject *obj, int nclasses, Py_buffer *view)
{
    if (PyObject_GetBuffer(obj, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return -1;
    const char *f = view->format ? view->format : "B";
    if (*f == '<' || *f == '=' || *f == '@')
        f++;
    char msg[PD_DIAG_MESSAGE_LEN] = "";
    if (view->ndim != 1 || view->itemsize != sizeof(int) || strcmp(f, "i") != 0 ||
        view->shape[0] != self->sim->nposes)
        snprintf(msg, sizeof msg, "classes: expected %d int32 class numbers, one per pose",
                 self->sim->nposes);
    const int *class_of = view->buf;
    for (int i = 0; !*msg && i < self->sim->nposes; i++)
        if (class_of[i] < 0 || class_of[i] >= nclasses)
            snprintf(msg, sizeof msg, "classes[%d] is %d: expected a class from 0 to %d", i,
                     class_of[i], nclasses - 1);
    if (*msg) {
        PyBuffer_Release(view);
        raise_status(PD_ERR_USAGE, msg);
        return -1;
    }
    return 0;
}

static PyObject *Drops_grouped(DropsObject *self, PyObject *args)
{
    PyObject *obj;
    int nclasses;
    Py_buffer view;
    if (!PyArg_ParseTuple(args, "Oi", &obj, &nclasses) ||
        read_classes(self, obj, nclasses, &view) < 0)
        return NULL;
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    pd_sim_result *g = NULL;
    pd_status st = pd_sim_result_grouped(self->sim, view.buf, nclasses, &g, &diag);
    PyBuffer_Release(&view);
    if (st != PD_OK)
        return fail(st, &diag, &w);
    if (diag_finish(&w) < 0) {
        pd_sim_result_free(g);
        return NULL;
    }
    return drops_new(g, &self->scene, self->part_size);
}

/* pd_sim_sensitivity of these drops (kept trials) in their scene, per pose
 * or, given (class_of, nclasses), per class: a dict of buffers, one entry
 * per row, pose-major, as --sensitivity writes them. */
static PyObject *Drops_sensitivity(DropsObject *self, PyObject *args)
{
    PyObject *obj = Py_None;
    int nclasses = 0;
    Py_buffer view = {0};
    if (!PyArg_ParseTuple(args, "|Oi", &obj, &nclasses) ||
        (obj != Py_None && read_classes(self, obj, nclasses, &view) < 0))
        return NULL;
    warn_box w;
    pd_diag diag;
    diag_start(&diag, &w);
    pd_sensitivity *s = NULL;
    pd_status st;
    Py_BEGIN_ALLOW_THREADS
    st = pd_sim_sensitivity(self->sim, &self->scene, self->part_size,
                            obj != Py_None ? view.buf : NULL, nclasses, &s, &diag);
    Py_END_ALLOW_THREADS
    if (obj != Py_None)
        PyBuffer_Release(&view);
    if (st != PD_OK)
        return fail(st, &diag, &w);
    if (diag_finish(&w) < 0) {
        pd_sensitivity_free(s);
        return NULL;
    }
    size_t m = (size_t)s->nposes * (size_t)s->nparams;
    PyObject *d = PyDict_New(), *params = d ? PyList_New(0) : NULL;
    int bad = !d || put(d, "params", params) || put(d, "n", PyLong_FromLong(s->n)) ||
              put(d, "nposes", PyLong_FromLong(s->nposes));
    for (int k = 0; !bad && k < s->nparams; k++) {
        PyObject *name = PyUnicode_FromString(pd_scene_param_name(s->param[k]));
        bad = !name || PyList_Append(params, name) < 0;
        Py_XDECREF(name);
    }
    void *pose = NULL, *nlow = NULL, *nhigh = NULL, *v = NULL;
    bad = bad || put(d, "pose", new_buffer(m, sizeof(int32_t), &pose)) ||
          put(d, "n_low", new_buffer(m, sizeof(int64_t), &nlow)) ||
          put(d, "n_high", new_buffer(m, sizeof(int64_t), &nhigh)) ||
          put(d, "values", new_buffer(9 * m, sizeof(double), &v));
    for (size_t i = 0; !bad && i < m; i++) {
        const pd_sensitivity_row *r = &s->rows[i];
        const double row[9] = {r->p_low,  r->p_low_lo,  r->p_low_hi, r->p_high,  r->p_high_lo,
                               r->p_high_hi, r->index, r->index_lo, r->index_hi};
        ((int32_t *)pose)[i] = r->pose;
        ((int64_t *)nlow)[i] = r->n_low;
        ((int64_t *)nhigh)[i] = r->n_high;
        memcpy((double *)v + 9 * i, row, sizeof row);
    }
    pd_sensitivity_free(s);
    if (bad) {
        Py_XDECREF(d);
        return NULL;
    }
    return d;
}

/* --- module ------------------------------------------------------------ */

static PyObject *mod_version(PyObject *mod, PyObject *unused)
{
    (void)mod;
    (void)unused;
    return PyUnicode_FromString(pd_version());
}

static PyObject *mod_statuses(PyObject *mod, PyObject *unused)
{
    (void)mod;
    (void)unused;
#define STATUS(name) {#name, name}
    static const struct {
        const char *name;
        pd_status value;
    } table[] = {
        STATUS(PD_OK), STATUS(PD_ERR_USAGE), STATUS(PD_ERR_IO), STATUS(PD_ERR_FORMAT),
        STATUS(PD_ERR_PARSE), STATUS(PD_ERR_NONFINITE), STATUS(PD_ERR_RANGE),
        STATUS(PD_ERR_TOO_FEW_POINTS), STATUS(PD_ERR_COLOCATED), STATUS(PD_ERR_COLLINEAR),
        STATUS(PD_ERR_COPLANAR), STATUS(PD_ERR_NOT_CLOSED), STATUS(PD_ERR_ORIENTATION),
        STATUS(PD_ERR_COM_OUTSIDE), STATUS(PD_ERR_NO_CONVERGENCE), STATUS(PD_ERR_NOMEM),
        STATUS(PD_ERR_INTERNAL), STATUS(PD_ERR_UNAVAILABLE), STATUS(PD_ERR_CANCELLED),
    };
#undef STATUS
    _Static_assert(sizeof table / sizeof table[0] == PD_STATUS_COUNT, "every status is listed");
    PyObject *d = PyDict_New();
    for (size_t i = 0; d && i < sizeof table / sizeof table[0]; i++)
        if (put(d, table[i].name + 3, PyLong_FromLong(table[i].value)) < 0)
            Py_CLEAR(d);
    return d;
}

/* A tuple of n names, name(i) for i in 0..n-1. */
static PyObject *name_tuple(int n, const char *(*name)(int))
{
    PyObject *t = PyTuple_New(n);
    for (int i = 0; t && i < n; i++) {
        PyObject *x = PyUnicode_FromString(name(i));
        if (!x)
            Py_CLEAR(t);
        else
            PyTuple_SET_ITEM(t, i, x);
    }
    return t;
}

static const char *stage_name(int i) { return pd_drop_stage_name((pd_drop_stage)i); }
static const char *status_text(int i) { return pd_status_str((pd_status)i); }
static const char *param_name(int i) { return pd_scene_param_name((pd_scene_param)i); }

/* The library's names by number: drop stages (pd_drop_stage_name),
 * statuses (pd_status_str) and ranged scene parameters
 * (pd_scene_param_name). */
static PyObject *mod_names(PyObject *mod, PyObject *unused)
{
    (void)mod;
    (void)unused;
    return Py_BuildValue("(NNN)", name_tuple(PD_STAGE_COUNT, stage_name),
                         name_tuple(PD_STATUS_COUNT, status_text),
                         name_tuple(PD_NPARAMS, param_name));
}

static PyObject *mod_engine_available(PyObject *mod, PyObject *arg)
{
    (void)mod;
    int e = 0;
    if (choose("engine", engine_names, arg, &e) < 0)
        return NULL;
    return PyBool_FromLong(pd_engine_available((pd_engine_kind)e));
}

static PyMethodDef Part_methods[] = {
    {"info", (PyCFunction)Part_info, METH_NOARGS, "the part's properties as a dict"},
    {"mesh", (PyCFunction)Part_mesh, METH_NOARGS, "(vertices, faces) buffers of the welded mesh"},
    {"hull", (PyCFunction)Part_hull, METH_NOARGS, "the convex hull as a dict of buffers"},
    {"estimate", (PyCFunction)(void (*)(void))Part_estimate, METH_VARARGS | METH_KEYWORDS,
     "pd_static_estimate"},
    {NULL, NULL, 0, NULL}};

static PyMethodDef Poses_methods[] = {
    {"poses", (PyCFunction)Poses_poses, METH_NOARGS, "the stable poses as a dict of buffers"},
    {"facets", (PyCFunction)Poses_facets, METH_NOARGS, "the hull facets as a dict of buffers"},
    {"classes", (PyCFunction)Poses_classes, METH_NOARGS, "pd_pose_classes: (buffer, nclasses)"},
    {"drop", (PyCFunction)(void (*)(void))Poses_drop, METH_VARARGS | METH_KEYWORDS, "pd_sim_run"},
    {NULL, NULL, 0, NULL}};

static PyMethodDef Drops_methods[] = {
    {"arrays", (PyCFunction)Drops_arrays, METH_NOARGS, "the result as a dict of buffers"},
    {"grouped", (PyCFunction)Drops_grouped, METH_VARARGS, "pd_sim_result_grouped"},
    {"sensitivity", (PyCFunction)Drops_sensitivity, METH_VARARGS, "pd_sim_sensitivity"},
    {NULL, NULL, 0, NULL}};

static PyMemberDef Poses_members[] = {
    {"part", T_OBJECT, offsetof(PosesObject, part), READONLY, "the part"},
    {NULL, 0, 0, 0, NULL}};

static PyTypeObject PartType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "posedrop._posedrop.PartHandle",
    .tp_basicsize = sizeof(PartObject),
    .tp_dealloc = (destructor)Part_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A built pd_part (immutable).",
    .tp_methods = Part_methods,
};

static PyTypeObject PosesType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "posedrop._posedrop.PosesHandle",
    .tp_basicsize = sizeof(PosesObject),
    .tp_dealloc = (destructor)Poses_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A pd_static_result with the part it was computed for.",
    .tp_methods = Poses_methods,
    .tp_members = Poses_members,
};

static PyTypeObject DropsType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "posedrop._posedrop.DropsHandle",
    .tp_basicsize = sizeof(DropsObject),
    .tp_dealloc = (destructor)Drops_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A pd_sim_result.",
    .tp_methods = Drops_methods,
};

static PyMethodDef module_methods[] = {
    {"part_from_file", (PyCFunction)(void (*)(void))part_from_file, METH_VARARGS | METH_KEYWORDS,
     "pd_mesh_read then pd_part_build"},
    {"part_from_arrays", (PyCFunction)(void (*)(void))part_from_arrays,
     METH_VARARGS | METH_KEYWORDS, "pd_part_build from (n, 3) float64 and (m, 3) int32 buffers"},
    {"version", mod_version, METH_NOARGS, "pd_version()"},
    {"statuses", mod_statuses, METH_NOARGS, "the pd_status names and values"},
    {"engine_available", mod_engine_available, METH_O, "pd_engine_available"},
    {"names", mod_names, METH_NOARGS, "(stage names, status strings, parameter names)"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module_def = {PyModuleDef_HEAD_INIT, "posedrop._posedrop",
                                        "The C core of the posedrop package.", -1,
                                        module_methods, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__posedrop(void)
{
    if (PyType_Ready(&PartType) < 0 || PyType_Ready(&PosesType) < 0 ||
        PyType_Ready(&DropsType) < 0)
        return NULL;
    /* The exceptions are Python classes (posedrop/_errors.py), so that they
     * carry docstrings and pickle like any other. */
    PyObject *errors = PyImport_ImportModule("posedrop._errors");
    if (!errors)
        return NULL;
    input_error = PyObject_GetAttrString(errors, "InputError");
    internal_error = PyObject_GetAttrString(errors, "InternalError");
    posedrop_warning = PyObject_GetAttrString(errors, "PosedropWarning");
    Py_DECREF(errors);
    if (!input_error || !internal_error || !posedrop_warning)
        return NULL;
    /* Every engine the command offers. */
    pd_status st = pd_bullet_register();
    if (st != PD_OK)
        return raise_status(st, "the Bullet engine could not be registered");
    return PyModule_Create(&module_def);
}
