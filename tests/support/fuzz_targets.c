/* fuzz_targets.c: the fuzz targets' bodies (see fuzz_targets.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "fuzz_targets.h"
#include "cli/shard_read.h"
#include "posedrop/posedrop.h"
#include "sim/scene.h"
#include "viz/viz.h"

/* A reader's answer: on success a mesh whose indices are in range and whose
 * coordinates are finite; on failure no mesh and a message. */
static int check_mesh(pd_status st, const pd_mesh *m, const pd_diag *d)
{
    if (st != PD_OK)
        return m == NULL && d->message[0] != '\0' &&
               (pd_status_is_input_error(st) || st == PD_ERR_NOMEM);
    if (!m || m->nverts <= 0 || m->ntris <= 0)
        return 0;
    for (int t = 0; t < m->ntris; t++)
        for (int c = 0; c < 3; c++)
            if (m->tris[t][c] < 0 || m->tris[t][c] >= m->nverts)
                return 0;
    for (int v = 0; v < m->nverts; v++)
        if (!isfinite(m->verts[v].x) || !isfinite(m->verts[v].y) || !isfinite(m->verts[v].z))
            return 0;
    return 1;
}

static int read_as(const uint8_t *data, size_t size, pd_mesh_format format, const char *name)
{
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    ro.format = format;
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_mesh_parse(data, size, name, &ro, &m, &d);
    int ok = check_mesh(st, m, &d);
    pd_mesh_free(m);
    return ok;
}

int pd_fuzz_off(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_OFF, "fuzz.off");
}

int pd_fuzz_stl(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_STL, "fuzz.stl");
}

int pd_fuzz_obj(const uint8_t *data, size_t size)
{
    return read_as(data, size, PD_FORMAT_OBJ, "fuzz.obj");
}

/* A scene: accepted values within their ranges, or the scene untouched. */
int pd_fuzz_scene(const uint8_t *data, size_t size)
{
    pd_scene s, before;
    pd_scene_default(&s);
    before = s;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_scene_parse(data, size, "fuzz.scene", &s, &d);
    if (st != PD_OK)
        return memcmp(&s, &before, sizeof s) == 0 && d.message[0] != '\0';
    return s.height >= 0 && s.height <= 1e3 && s.mu >= 0 && s.mu <= 10 && s.restitution >= 0 &&
           s.restitution <= 1 && s.gravity > 0 && isfinite(s.belt_speed) && s.vibration >= 0 &&
           (s.contact_time >= 0 || s.contact_time == PD_CONTACT_TIME_AUTO) &&
           pd_scene_check(&s, NULL) == PD_OK;
}

/* Mesh in (any format, by content), part model out, then its static
 * estimate: probabilities that sum to one, or a clear refusal. */
int pd_fuzz_part(const uint8_t *data, size_t size)
{
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_mesh_parse(data, size, "fuzz", NULL, &m, &d);
    if (st != PD_OK)
        return check_mesh(st, m, &d);
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    pd_part_options po;
    pd_part_options_default(&po);
    st = pd_part_build(m, &po, &part, &d);
    if (st == PD_OK)
        st = pd_static_estimate(part, NULL, &res, &d);
    int ok = st == PD_OK ? res != NULL : d.message[0] != '\0';
    if (st == PD_OK && res) {
        double qs = 0.0, pqs = 0.0;
        for (int i = 0; i < res->nposes; i++) {
            qs += res->poses[i].p_qs;
            pqs += res->poses[i].p_pqs;
            ok &= isfinite(res->poses[i].normal.x) && res->poses[i].area >= 0;
        }
        /* A distribution over the poses, to round-off of the sum. */
        ok &= res->nposes >= 1 && fabs(qs - 1.0) < 1e-9 && fabs(pqs - 1.0) < 1e-9;
    }
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(m);
    return ok;
}

/* --- the library API: sequences of calls ------------------------------------ */

/* The input is a program: each byte picks a call, the bytes after it its
 * arguments (slots of earlier results, NULLs, enum values in and out of
 * range, numbers from a table of edge cases or raw bits). Objects of
 * different calls are paired at random, so a static result meets parts it
 * was not computed from and a shard sums into another run's. Every call
 * must answer well-formed: a status of the documented set; on failure a
 * message and its outputs untouched; PD_ERR_USAGE for a NULL it needs; on
 * success a result that holds together. */

/* A program's drops are its cost: a drop that never settles (a tilt of half
 * a turn, a pose table from another part) runs to its time or collision
 * limit, a hundredth of a second in the optimised build and about a hundred
 * times that under the sanitizers and the fuzzer's coverage, so a program
 * may drop FZ_DROPS times in all, each for at most FZ_DROP_TIME simulated
 * seconds (a fall of a metre) and FZ_COLLISIONS collisions. Beyond them a
 * program is a slow run, not a finding (an input may take 10 s). */
enum { FZ_SLOTS = 4, FZ_MAX_CALLS = 48, FZ_DROPS = 8, FZ_COLLISIONS = 300 };
#define FZ_DROP_TIME 0.5

typedef struct {
    const uint8_t *p;
    size_t n;
} fz_in;

static unsigned fz_byte(fz_in *in)
{
    if (!in->n)
        return 0;
    in->n--;
    return *in->p++;
}

static int fz_pick(fz_in *in, int k)
{
    return (int)(fz_byte(in) % (unsigned)k);
}

/* One time in 16, NULL. */
static int fz_null(fz_in *in)
{
    return fz_pick(in, 16) == 0;
}

static int fz_int(fz_in *in)
{
    uint32_t u = 0;
    for (int i = 0; i < 4; i++)
        u |= (uint32_t)fz_byte(in) << (8 * i);
    return (int)u;
}

/* A small integer around [lo, hi], now and then anything. */
static int fz_small(fz_in *in, int lo, int hi)
{
    unsigned b = fz_byte(in);
    return b >= 0xf8 ? fz_int(in) : lo + (int)(b % (unsigned)(hi - lo + 1));
}

/* An enum value: one of its n values seven times in eight, else one beyond
 * either end. */
static int fz_enum(fz_in *in, int n)
{
    unsigned b = fz_byte(in);
    return b % 8 ? (int)(b / 8 % (unsigned)n) : b & 8 ? n : -1;
}

static double fz_real(fz_in *in)
{
    static const double table[] = {0.0,  1.0,   -1.0,  0.5,     1e-3,    0.12,  9.81,
                                   0.3,  1e-320, -0.0, NAN,     INFINITY, -INFINITY, 1e300,
                                   2.0,  10.0,  1e3,   0.01,    1e-9,    M_PI,  0.05,
                                   -1e-9, 0.0049, 1e-7, 0.5 * M_PI, 1e30, 1e-30, 0.0};
    unsigned b = fz_byte(in);
    if (b < 0xf0)
        return table[b % (sizeof table / sizeof table[0])];
    uint64_t u = 0;
    for (int i = 0; i < 8; i++)
        u |= (uint64_t)fz_byte(in) << (8 * i);
    double x;
    memcpy(&x, &u, sizeof x);
    return x;
}

/* Small parts, convex and not, of a few cm. */
static const char *const fz_shapes[] = {
    "OFF\n4 4 0\n0 0 0\n0.01 0 0\n0 0.01 0\n0 0 0.01\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    "OFF\n8 6 0\n0 0 0\n0.01 0 0\n0.01 0.01 0\n0 0.01 0\n0 0 0.01\n0.01 0 0.01\n0.01 0.01 0.01\n"
    "0 0.01 0.01\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    "OFF\n8 6 0\n0 0 0\n0.01 0 0\n0.01 0.02 0\n0 0.02 0\n0 0 0.03\n0.01 0 0.03\n0.01 0.02 0.03\n"
    "0 0.02 0.03\n4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n",
    "OFF\n12 10 0\n0 0 0\n0.03 0 0\n0.03 0.005 0\n0.005 0.005 0\n0.005 0.03 0\n0 0.03 0\n"
    "0 0 0.02\n0.03 0 0.02\n0.03 0.005 0.02\n0.005 0.005 0.02\n0.005 0.03 0.02\n0 0.03 0.02\n"
    "4 0 3 2 1\n4 0 5 4 3\n4 7 8 9 6\n4 9 10 11 6\n4 0 1 7 6\n4 1 2 8 7\n4 2 3 9 8\n"
    "4 3 4 10 9\n4 4 5 11 10\n4 5 0 6 11\n",
    "OFF\n6 8 0\n0.01 0 0\n-0.01 0 0\n0 0.01 0\n0 -0.01 0\n0 0 0.01\n0 0 -0.01\n"
    "3 0 2 4\n3 2 1 4\n3 1 3 4\n3 3 0 4\n3 2 0 5\n3 1 2 5\n3 3 1 5\n3 0 3 5\n",
};

typedef struct {
    pd_mesh *mesh[FZ_SLOTS];
    int vcap[FZ_SLOTS], tcap[FZ_SLOTS]; /* what the mesh's arrays hold */
    pd_part *part[FZ_SLOTS];
    pd_static_result *res[FZ_SLOTS];
    int pcap[FZ_SLOTS]; /* poses the result's array holds */
    int of[FZ_SLOTS];   /* the part slot the result was computed from */
    pd_sim_result *sim[FZ_SLOTS];
    int ok;
    long calls;
    long drops; /* run so far, against FZ_DROPS */
} fz_state;

/* A failed call's answer: a status of the set, a message, outputs as they
 * were. A NULL the call needs must be PD_ERR_USAGE. */
static int fz_failed_well(pd_status st, const pd_diag *d, int untouched, int needed_null)
{
    return st > PD_OK && st < PD_STATUS_COUNT && d->message[0] != '\0' && untouched &&
           (!needed_null || st == PD_ERR_USAGE);
}

static int fz_answer(pd_status st, const pd_diag *d, int untouched, int needed_null)
{
    if (needed_null)
        return st == PD_ERR_USAGE && fz_failed_well(st, d, untouched, 1);
    return st == PD_OK || fz_failed_well(st, d, untouched, 0);
}

static void fz_static_options(fz_in *in, pd_static_options *o)
{
    pd_static_options_default(o);
    o->topple = (pd_topple_rule)fz_enum(in, 2);
    o->compare = (pd_pqs_compare)fz_enum(in, 2);
    o->band = (pd_pqs_band)fz_enum(in, 2);
    if (fz_pick(in, 4) == 0)
        o->epsilon = fz_real(in);
}

static void fz_scene(fz_in *in, pd_scene *s)
{
    pd_scene_default(s);
    for (int k = fz_pick(in, 4); k > 0; k--) {
        double x = fz_real(in);
        switch (fz_pick(in, 9)) {
        case 0: s->height = x; break;
        case 1: s->belt_speed = x; break;
        case 2: s->mu = x; break;
        case 3: s->restitution = x; break;
        case 4: s->law = (pd_restitution_law)fz_enum(in, 2); break;
        case 5: s->vibration = x; break;
        case 6: s->initial = (pd_initial)fz_enum(in, 3); break;
        case 7: s->gravity = x; break;
        default: s->contact_time = fz_pick(in, 2) ? PD_CONTACT_TIME_AUTO : x; break;
        }
    }
}

/* Options for a run of at most a few short drops, with any field spoiled
 * now and then. */
static void fz_sim_options(fz_in *in, pd_sim_options *o)
{
    static const double dts[] = {0.0, 1e-3, 5e-3, 0.01, -1e-3, NAN, 0.02};
    static const double limits[] = {FZ_DROP_TIME, 0.25, 0.1, FZ_DROP_TIME, 0.25, 0.0, -1.0, NAN};
    pd_sim_options_default(o);
    /* Counts stay small (a huge one would be a slow run, not a finding). */
    o->ndrops = fz_pick(in, 16) ? fz_pick(in, 4) : -1;
    o->threads = 1 + fz_pick(in, 2);
    o->seed = fz_byte(in);
    o->time_limit = limits[fz_pick(in, 8)];
    o->max_collisions = fz_small(in, 0, FZ_COLLISIONS);
    if (o->max_collisions > FZ_COLLISIONS)
        o->max_collisions = FZ_COLLISIONS;
    if (fz_pick(in, 4) == 0) {
        o->engine = (pd_engine_kind)fz_enum(in, 3);
        o->dt = dts[fz_pick(in, 7)];
    }
    if (fz_pick(in, 4) == 0) {
        o->ci_halfwidth = fz_pick(in, 2) ? 0.45 : fz_real(in);
        o->max_drops = fz_pick(in, 16) ? fz_pick(in, 5) : -1;
    }
    if (fz_pick(in, 4) == 0) {
        o->nshards = fz_small(in, -1, 3);
        o->shard = fz_small(in, -1, 3);
    }
    o->keep_trials = fz_enum(in, 2);
}

static void fz_drop_mesh(fz_state *s, int k)
{
    pd_mesh_free(s->mesh[k]);
    s->mesh[k] = NULL;
}

static void fz_call_mesh(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS), shape = fz_pick(in, 5);
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    ro.format = (pd_mesh_format)(fz_pick(in, 8) == 0 ? 9 : fz_pick(in, 2) ? PD_FORMAT_OFF : 0);
    ro.units = (pd_units)fz_enum(in, 4);
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    int null_out = fz_null(in);
    pd_status st = pd_mesh_parse(fz_shapes[shape], strlen(fz_shapes[shape]), "fuzz.off", &ro,
                                 null_out ? NULL : &m, &d);
    int bad_options = (unsigned)ro.format > PD_FORMAT_OBJ || (unsigned)ro.units > PD_UNITS_IN;
    s->ok &= fz_answer(st, &d, m == NULL, null_out) && (!bad_options || st == PD_ERR_USAGE);
    if (st == PD_OK && m) {
        s->ok &= check_mesh(st, m, &d);
        fz_drop_mesh(s, k);
        s->mesh[k] = m;
        s->vcap[k] = m->nverts;
        s->tcap[k] = m->ntris;
    }
}

/* Changes a mesh as a program could: a coordinate, an index, a count (never
 * beyond what its arrays hold). */
static void fz_call_mutate_mesh(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS);
    pd_mesh *m = s->mesh[k];
    if (!m || s->vcap[k] < 1 || s->tcap[k] < 1)
        return;
    int v = fz_pick(in, s->vcap[k]), t = fz_pick(in, s->tcap[k]), n;
    switch (fz_pick(in, 5)) {
    case 0: m->verts[v].x = fz_real(in); break;
    case 1: m->verts[v].y += fz_real(in) * 0.01; break;
    case 2: m->tris[t][fz_pick(in, 3)] = fz_small(in, -2, s->vcap[k] + 1); break;
    case 3:
        n = fz_small(in, -4, s->vcap[k]);
        m->nverts = n < s->vcap[k] ? n : s->vcap[k];
        break;
    default:
        n = fz_small(in, -2, s->tcap[k]);
        m->ntris = n < s->tcap[k] ? n : s->tcap[k];
        break;
    }
}

static void fz_call_weld_orient_mass(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS), what = fz_pick(in, 3);
    pd_mesh *m = fz_null(in) ? NULL : s->mesh[k];
    pd_diag d;
    pd_diag_init(&d);
    int n = -7;
    pd_status st;
    if (what == 0) {
        double tol = fz_real(in) * 1e-3;
        st = pd_mesh_weld(m, tol, fz_null(in) ? NULL : &n);
        /* No diag: only the status and the count are checked. */
        s->ok &= st >= PD_OK && st < PD_STATUS_COUNT && (st == PD_OK || n == -7) &&
                 (m || st == PD_ERR_USAGE) && (tol >= 0 && isfinite(tol) ? 1 : st != PD_OK);
    } else if (what == 1) {
        st = pd_mesh_orient(m, fz_null(in) ? NULL : &n, &d);
        s->ok &= fz_answer(st, &d, st == PD_OK || n == -7, m == NULL);
    } else {
        pd_mass mass, before;
        memset(&mass, 0x5a, sizeof mass);
        before = mass;
        int null_mass = fz_null(in);
        st = pd_mass_compute(m, null_mass ? NULL : &mass, &d);
        s->ok &= fz_answer(st, &d, st == PD_OK || memcmp(&mass, &before, sizeof mass) == 0,
                           m == NULL || null_mass);
        s->ok &= st != PD_OK || (mass.volume > 0 && isfinite(mass.com.x));
    }
    /* Weld and orient rebuild or flip the arrays of a mesh they accept. */
    if (st == PD_OK && m) {
        s->vcap[k] = m->nverts;
        s->tcap[k] = m->ntris;
    }
}

static void fz_call_part(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS), from = fz_pick(in, FZ_SLOTS);
    pd_part_options po;
    pd_part_options_default(&po);
    po.com_given = fz_pick(in, 4) == 0 ? fz_enum(in, 2) : 0;
    if (po.com_given)
        po.com = (pd_vec3){0.003 + fz_real(in) * 1e-3, 0.003, 0.003};
    const pd_mesh *m = fz_null(in) ? NULL : s->mesh[from];
    int null_out = fz_null(in);
    pd_part *p = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_part_build(m, fz_null(in) ? NULL : &po, null_out ? NULL : &p, &d);
    s->ok &= fz_answer(st, &d, p == NULL, m == NULL || null_out);
    if (st == PD_OK && p) {
        s->ok &= p->hull && p->hull->nfacets >= 4 && p->size > 0;
        pd_part_free(s->part[k]);
        s->part[k] = p;
    }
}

/* A static result: probabilities that sum to one over its poses. */
static int fz_static_sound(const pd_static_result *r)
{
    double qs = 0.0, pqs = 0.0;
    for (int i = 0; i < r->nposes; i++) {
        qs += r->poses[i].p_qs;
        pqs += r->poses[i].p_pqs;
    }
    return r->nposes >= 1 && fabs(qs - 1.0) < 1e-9 && fabs(pqs - 1.0) < 1e-9;
}

static void fz_call_static(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS), from = fz_pick(in, FZ_SLOTS);
    pd_static_options so;
    fz_static_options(in, &so);
    const pd_part *p = fz_null(in) ? NULL : s->part[from];
    int null_out = fz_null(in);
    pd_static_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_static_estimate(p, fz_null(in) ? NULL : &so, null_out ? NULL : &r, &d);
    s->ok &= fz_answer(st, &d, r == NULL, p == NULL || null_out);
    if (st == PD_OK && r) {
        s->ok &= fz_static_sound(r);
        pd_static_result_free(s->res[k]);
        s->res[k] = r;
        s->pcap[k] = r->nposes;
        s->of[k] = from;
    }
}

/* Edits a pose table as a program could: a pose's facet, the pose count. */
static void fz_call_mutate_static(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS);
    pd_static_result *r = s->res[k];
    if (!r || s->pcap[k] < 1)
        return;
    if (fz_pick(in, 2)) {
        r->poses[fz_pick(in, s->pcap[k])].facet = fz_small(in, -1, r->nfacets + 1);
    } else {
        int n = fz_small(in, -1, s->pcap[k]);
        r->nposes = n < s->pcap[k] ? n : s->pcap[k];
    }
}

/* A static result and a part: three times in four the part it was computed
 * from (if that slot still holds the same part), else any. */
static void fz_pair(fz_state *s, fz_in *in, const pd_part **p, const pd_static_result **r)
{
    int j = fz_pick(in, FZ_SLOTS), i = fz_pick(in, 4) ? s->of[j] : fz_pick(in, FZ_SLOTS);
    *r = fz_null(in) ? NULL : s->res[j];
    *p = fz_null(in) ? NULL : s->part[i];
}

static void fz_call_symmetry(fz_state *s, fz_in *in)
{
    const pd_part *p;
    const pd_static_result *r;
    fz_pair(s, in, &p, &r);
    pd_diag d;
    pd_diag_init(&d);
    if (fz_pick(in, 2)) {
        int null_out = fz_null(in);
        pd_symmetry *sym = NULL;
        pd_status st = pd_symmetry_find(p, null_out ? NULL : &sym, &d);
        s->ok &= fz_answer(st, &d, sym == NULL, p == NULL || null_out);
        s->ok &= st != PD_OK || (sym && sym->nrotations >= 1);
        pd_symmetry_free(sym);
        return;
    }
    int room = r && r->nposes > 0 ? r->nposes : 1;
    int *cls = malloc(sizeof *cls * (size_t)room), n = -7;
    if (!cls)
        return;
    for (int i = 0; i < room; i++)
        cls[i] = -7;
    int null_cls = fz_null(in), null_n = fz_null(in);
    pd_status st = pd_pose_classes(p, r, null_cls ? NULL : cls, null_n ? NULL : &n, &d);
    s->ok &= fz_answer(st, &d, n == -7, !p || !r || null_cls || null_n);
    if (st == PD_OK) {
        /* A pose table edited down to no pose has no class. */
        s->ok &= n >= (r->nposes > 0) && n <= r->nposes;
        for (int i = 0; i < r->nposes; i++)
            s->ok &= cls[i] >= 0 && cls[i] < n;
    }
    free(cls);
}

/* A run's counts: every drop counted once, probabilities in [0, 1]. */
static int fz_sim_sound(const pd_sim_result *r)
{
    long sum = r->unsettled;
    int ok = r->n >= 0 && r->nposes >= 1;
    for (int i = 0; i < r->nposes; i++) {
        sum += r->count[i];
        ok &= r->p[i] >= 0 && r->p[i] <= 1 && r->ci_lo[i] <= r->ci_hi[i];
    }
    return ok && sum == r->n;
}

static void fz_keep_sim(fz_state *s, int k, pd_sim_result *r)
{
    pd_sim_result_free(s->sim[k]);
    s->sim[k] = r;
}

static void fz_call_sim(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS);
    const pd_part *p;
    const pd_static_result *poses;
    fz_pair(s, in, &p, &poses);
    pd_scene sc;
    fz_scene(in, &sc);
    pd_sim_options o;
    fz_sim_options(in, &o);
    /* A stepping engine's automatic step follows the contact time, which
     * scales with the part: a drop of a built-in shape read in millimetres
     * (10-40 um across) takes 10^5-10^7 steps, a quarter of a second in the
     * optimised build. Parts under a centimetre take their automatic step
     * on the impulse engine, whose cost does not depend on a step. */
    if ((o.engine == PD_ENGINE_ODE || o.engine == PD_ENGINE_BULLET) && o.dt == 0.0 && p &&
        !(p->size >= 1e-2))
        o.engine = PD_ENGINE_IMPULSE;
    /* The automatic time limit, a hundred falls, only where it is within the
     * program's for the scene drawn and for the default one (a NULL scene
     * below); and the drops the program has left. */
    if (o.time_limit == 0.0 && p &&
        !(fmax(pd_time_limit_auto(p->size, &sc), pd_time_limit_auto(p->size, NULL)) <=
          FZ_DROP_TIME))
        o.time_limit = FZ_DROP_TIME;
    long left = FZ_DROPS - s->drops;
    if (o.ndrops > left)
        o.ndrops = left;
    if (o.max_drops > left)
        o.max_drops = left;
    int null_out = fz_null(in), null_scene = fz_null(in), null_opt = fz_pick(in, 64) == 0;
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st;
    if (fz_pick(in, 3) == 0) {
        st = pd_sim_result_new(poses, null_scene ? NULL : &sc, null_opt ? NULL : &o,
                               null_out ? NULL : &r, &d);
        s->ok &= fz_answer(st, &d, r == NULL, !poses || null_out);
        s->ok &= st != PD_OK || (r && r->n == 0);
    } else {
        if (null_opt)
            o.ndrops = 0; /* the defaults' 2000 drops would be slow here */
        st = pd_sim_run(p, poses, null_scene ? NULL : &sc, &o, null_out ? NULL : &r, &d);
        s->ok &= fz_answer(st, &d, r == NULL, !p || !poses || null_out);
        s->ok &= st != PD_OK || (r && fz_sim_sound(r) && r->n <= o.ndrops + o.max_drops + 2000);
    }
    if (r)
        s->drops += r->n;
    if (st == PD_OK && r)
        fz_keep_sim(s, k, r);
}

static void fz_call_sums(fz_state *s, fz_in *in)
{
    pd_sim_result *a = fz_null(in) ? NULL : s->sim[fz_pick(in, FZ_SLOTS)];
    const pd_sim_result *b = fz_null(in) ? NULL : s->sim[fz_pick(in, FZ_SLOTS)];
    pd_diag d;
    pd_diag_init(&d);
    int what = fz_pick(in, 3);
    if (what == 0) {
        long n = a ? a->n : 0;
        pd_status st = pd_sim_result_add(a, b, &d);
        s->ok &= fz_answer(st, &d, !a || a->n == n, !a || !b);
    } else if (what == 1) {
        pd_status st = pd_sim_result_finish(a, &d);
        s->ok &= fz_answer(st, &d, 1, !a);
        s->ok &= st != PD_OK || fz_sim_sound(a);
    } else {
        /* class_of has room for a's poses, as the header asks. */
        int room = a && a->nposes > 0 ? a->nposes : 1, nclasses = fz_small(in, -1, 4);
        int *cls = malloc(sizeof *cls * (size_t)room);
        if (!cls)
            return;
        for (int i = 0; i < room; i++)
            cls[i] = fz_small(in, -1, 3);
        int null_cls = fz_null(in), null_out = fz_null(in);
        pd_sim_result *g = NULL;
        pd_status st = pd_sim_result_grouped(a, null_cls ? NULL : cls, nclasses,
                                             null_out ? NULL : &g, &d);
        s->ok &= fz_answer(st, &d, g == NULL, !a || null_cls || null_out);
        s->ok &= st != PD_OK || (g && g->nposes == nclasses && g->n == a->n);
        if (st == PD_OK && g && nclasses >= 1)
            fz_keep_sim(s, fz_pick(in, FZ_SLOTS), g);
        else
            pd_sim_result_free(g);
        free(cls);
    }
}

static void fz_call_hull(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS);
    const pd_mesh *m = s->mesh[k];
    /* The points of a mesh, as many as its array holds at most. */
    const pd_vec3 *pts = m && !fz_null(in) ? m->verts : NULL;
    int npts = m ? fz_small(in, -1, s->vcap[k]) : 0;
    if (npts > s->vcap[k])
        npts = s->vcap[k];
    pd_hull *h = NULL;
    pd_diag d;
    pd_diag_init(&d);
    int null_out = fz_null(in);
    pd_status st = pd_hull_build(pts, npts, null_out ? NULL : &h, &d);
    s->ok &= fz_answer(st, &d, h == NULL, null_out || (!pts && npts > 0));
    pd_diag_init(&d);
    const pd_hull *given = fz_null(in) ? NULL : h;
    st = pd_hull_check(given, fz_null(in) ? NULL : pts, npts, &d);
    s->ok &= fz_answer(st, &d, 1, given == NULL);
    /* A hull of these points is valid by its own check. */
    s->ok &= !given || st == PD_OK;
    pd_hull_free(h);
}

/* The calls on plain values: each answers something for anything. */
static void fz_call_values(fz_state *s, fz_in *in)
{
    int i = fz_int(in);
    double x = fz_real(in);
    static const char *const texts[] = {"m", "cm", "mm", "in", "ft", "", NULL};
    static const char *const keys[] = {"mu", "height", "initial", "restitution_law",
                                       "contact_time", "nope", NULL};
    static const char *const values[] = {"0.5", "auto", "stationary", "1e-320", "-1", "nan",
                                         "energetic", "", NULL};
    pd_units u = (pd_units)77;
    pd_status st = pd_units_parse(texts[fz_pick(in, 7)], fz_null(in) ? NULL : &u);
    s->ok &= (st == PD_OK) == ((unsigned)u <= PD_UNITS_IN);
    double scale = pd_units_scale((pd_units)i);
    s->ok &= (unsigned)i <= PD_UNITS_IN ? scale > 0 : scale == 0.0;
    s->ok &= pd_status_str((pd_status)i) != NULL && pd_version() != NULL;
    s->ok &= pd_status_is_input_error((pd_status)i) == 0 || pd_status_is_input_error((pd_status)i) == 1;
    s->ok &= pd_engine_available((pd_engine_kind)i) == ((unsigned)i <= PD_ENGINE_ODE);
    long drop = (long)i * fz_small(in, -3, 3);
    int nshards = fz_small(in, -1, 5), shard = fz_small(in, -1, 5);
    int of = pd_shard_of(drop, nshards);
    s->ok &= drop < 0 ? of == -1 : nshards < 1 ? of == 0 : of >= 0 && of < nshards;
    long nd = pd_shard_drops(drop, shard, nshards);
    s->ok &= nd >= 0 && (drop < 0 || nd <= drop);
    pd_vec3 a = {x, 1, 0}, b = {0, fz_real(in), 1}, c = {1, 0, fz_real(in)};
    (void)pd_solid_angle_triangle(a, b, c);
    (void)pd_contact_time_auto(x);

    pd_scene sc, before;
    fz_scene(in, &sc);
    before = sc;
    pd_diag d;
    pd_diag_init(&d);
    int null_scene = fz_null(in);
    const char *key = keys[fz_pick(in, 7)], *value = values[fz_pick(in, 9)];
    st = pd_scene_set(null_scene ? NULL : &sc, key, value, &d);
    s->ok &= fz_answer(st, &d, memcmp(&sc, &before, sizeof sc) == 0,
                       null_scene || !key || !value);
    pd_diag_init(&d);
    st = pd_scene_check(fz_null(in) ? NULL : &sc, &d);
    s->ok &= fz_answer(st, &d, 1, 0);
    pd_static_options so;
    fz_static_options(in, &so);
    pd_diag_init(&d);
    st = pd_static_options_check(&so, &d);
    s->ok &= fz_answer(st, &d, 1, 0) &&
             (st == PD_OK) == ((unsigned)so.topple <= PD_TOPPLE_EDGE &&
                               (unsigned)so.compare <= PD_PQS_COMPARE_QS &&
                               (unsigned)so.band <= PD_PQS_BAND_EXACT && so.epsilon >= 0 &&
                               so.epsilon <= 0.5 * M_PI);
    pd_sim_options o;
    fz_sim_options(in, &o);
    pd_diag_init(&d);
    st = pd_sim_options_check(fz_null(in) ? NULL : &o, &d);
    s->ok &= fz_answer(st, &d, 1, 0);
    pd_diag_init(fz_null(in) ? NULL : &d);
}

static void fz_call_free(fz_state *s, fz_in *in)
{
    int k = fz_pick(in, FZ_SLOTS);
    switch (fz_pick(in, 4)) {
    case 0: fz_drop_mesh(s, k); break;
    case 1:
        pd_part_free(s->part[k]);
        s->part[k] = NULL;
        break;
    case 2:
        pd_static_result_free(s->res[k]);
        s->res[k] = NULL;
        break;
    default: fz_keep_sim(s, k, NULL); break;
    }
}

int pd_fuzz_api(const uint8_t *data, size_t size)
{
    static void (*const calls[])(fz_state *, fz_in *) = {
        fz_call_mesh,   fz_call_mesh,      fz_call_mutate_mesh, fz_call_weld_orient_mass,
        fz_call_part,   fz_call_part,      fz_call_static,      fz_call_static,
        fz_call_mutate_static, fz_call_symmetry, fz_call_sim,   fz_call_sim,
        fz_call_sums,   fz_call_hull,      fz_call_values,      fz_call_free,
    };
    enum { NCALLS = sizeof calls / sizeof calls[0] };
    fz_state s;
    memset(&s, 0, sizeof s);
    s.ok = 1;
    fz_in in = {data, size};
    for (int i = 0; i < FZ_MAX_CALLS && in.n > 0 && s.ok; i++) {
        calls[fz_byte(&in) % NCALLS](&s, &in);
        s.calls++;
    }
    for (int k = 0; k < FZ_SLOTS; k++) {
        fz_drop_mesh(&s, k);
        pd_part_free(s.part[k]);
        pd_static_result_free(s.res[k]);
        pd_sim_result_free(s.sim[k]);
    }
    return s.ok;
}

/* The readers of files take a path: each input is written to one file of
 * the process's own, made on first use. NULL if it cannot be written. */
static char fuzz_path[64];

static void remove_fuzz_file(void)
{
    unlink(fuzz_path);
}

static const char *as_file(const uint8_t *data, size_t size)
{
    const char *path = fuzz_path;
    if (!fuzz_path[0]) {
        snprintf(fuzz_path, sizeof fuzz_path, "/tmp/posedrop-fuzz-%ld", (long)getpid());
        atexit(remove_fuzz_file);
    }
    FILE *f = fopen(path, "wb");
    if (!f)
        return NULL;
    int ok = fwrite(data, 1, size, f) == size;
    ok &= fclose(f) == 0;
    return ok ? path : NULL;
}

/* A measured table: probabilities in [0, 1] summing to 1, a count of
 * drops that is no overflow; or a refusal with a message. */
int pd_fuzz_measured(const uint8_t *data, size_t size)
{
    const char *path = as_file(data, size);
    if (!path)
        return 1; /* nothing to read: no answer to judge */
    viz_measured *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = viz_measured_read(path, &m, &d);
    if (st != PD_OK)
        return m == NULL && st < PD_STATUS_COUNT && d.message[0] != '\0';
    int ok = m && m->npose >= 1 && m->n >= 0;
    double sum = 0.0;
    for (int i = 0; ok && i < m->npose; i++) {
        ok = m->p[i] >= 0.0 && m->p[i] <= 1.0;
        sum += m->p[i];
        if (ok && m->lo)
            ok = m->lo[i] >= 0.0 && m->lo[i] <= m->hi[i] && m->hi[i] <= 1.0;
    }
    /* The file's p column may be off 1 by its stated tolerance. */
    ok = ok && fabs(sum - 1.0) < 0.01;
    viz_measured_free(m);
    return ok;
}

/* posedrop merge's reader of one shard: pose rows with counts that are no
 * overflow, as many as the header's run has poses; or a refusal. */
const char *prog = "fuzz";
int pd_fuzz_shard(const uint8_t *data, size_t size)
{
    const char *path = as_file(data, size);
    if (!path)
        return 1;
    shard_file s;
    int ok = 1;
    if (shard_read(path, &s)) {
        ok = s.nposes >= 1 && s.k >= 1 && s.k <= s.n && s.identity && s.version && !s.partial &&
             s.drops >= 0 && s.unsettled >= 0;
        for (int i = 0; ok && i < s.nposes; i++)
            ok = s.count[i] >= 0;
    }
    shard_file_clear(&s);
    return ok;
}
