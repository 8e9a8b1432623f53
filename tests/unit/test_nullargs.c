/* test_nullargs.c: every public function, called with each of its pointer
 * arguments NULL in turn (docs/library.md: NULL where an object is required
 * is PD_ERR_USAGE with a message, outputs untouched; NULL where the header
 * allows it, options, a diag or an optional output, is the documented
 * default).
 *
 * The table below says, for each function, the names of its pointer
 * parameters in order, '?' marking those that may be NULL. The test reads
 * the headers in include/posedrop/ and checks that every PD_API function is in the table
 * with exactly those pointer parameters, so a function added, or a pointer
 * parameter added to one, fails here until the table covers it. Each call
 * runs in a child process, so a crash names its function and argument. */
#include <ctype.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "engines/engine.h"
#include "files.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"

#define HEADERS "include/posedrop"
#define CUBE "parts/canonical/cube.off"

typedef struct {
    pd_mesh *mesh;          /* a closed cube */
    pd_part *part;
    pd_static_result *res;
    pd_sim_result *sim;     /* a few drops */
    int *class_of;
    int nclasses;
    char scene_path[64];    /* a scene file */
} fixture;

/* What one call did: its status (a pointer or number result is mapped onto
 * PD_OK or PD_ERR_USAGE by the caller), whether an output it must leave
 * alone on failure was written, and the message. */
typedef struct {
    pd_status st;
    int touched;
    pd_diag diag;
} outcome;

/* The pointer argument number `i` of a call, or NULL when it is the one
 * under test. */
#define P(i, x) (k == (i) ? NULL : (x))

/* An address no call may write through on failure, distinct from NULL. */
static char sentinel_byte;
#define SENTINEL ((void *)&sentinel_byte)

static void clear(outcome *o)
{
    memset(o, 0, sizeof *o); /* not pd_diag_init: it is under test too */
}

/* An output that began as SENTINEL: freed on success, unchanged on failure. */
#define settle_output(o, out, free_fn)                                                     \
    do {                                                                                   \
        if ((o)->st == PD_OK)                                                              \
            free_fn(out);                                                                  \
        else                                                                               \
            (o)->touched = (void *)(out) != SENTINEL;                                      \
    } while (0)

/* A *_free call: of the object, or of NULL (and then the object after). */
#define free_unless_null(k, object, free_fn)                                               \
    do {                                                                                   \
        free_fn(P(0, object));                                                             \
        if ((k) == 0)                                                                      \
            free_fn(object);                                                               \
    } while (0)

/* pd_NAME(&options) or pd_NAME(NULL), which must do nothing. */
#define DEFAULTS(name, type)                                                               \
    static void c_##name(const fixture *f, int k, outcome *o)                              \
    {                                                                                      \
        (void)f;                                                                           \
        type x;                                                                            \
        pd_##name(P(0, &x));                                                               \
        o->st = PD_OK;                                                                     \
    }

/* --- one function per public function ------------------------------------ */

static void c_bullet_register(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_bullet_register();
}

static void c_diag_init(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_diag_init(P(0, &o->diag));
    o->st = PD_OK;
}

static void c_hull_build(const fixture *f, int k, outcome *o)
{
    pd_hull *h = SENTINEL;
    o->st = pd_hull_build(P(0, f->mesh->verts), f->mesh->nverts, P(1, &h), P(2, &o->diag));
    settle_output(o, h, pd_hull_free);
}

static void c_hull_check(const fixture *f, int k, outcome *o)
{
    o->st = pd_hull_check(P(0, f->part->hull), P(1, f->part->mesh->verts), f->part->mesh->nverts,
                          P(2, &o->diag));
}

static void c_hull_free(const fixture *f, int k, outcome *o)
{
    pd_hull *h = NULL;
    o->st = pd_hull_build(f->mesh->verts, f->mesh->nverts, &h, NULL);
    free_unless_null(k, h, pd_hull_free);
}

static void c_mass_compute(const fixture *f, int k, outcome *o)
{
    pd_mass m, before;
    memset(&m, 0x5a, sizeof m);
    before = m;
    o->st = pd_mass_compute(P(0, f->mesh), P(1, &m), P(2, &o->diag));
    o->touched = o->st != PD_OK && memcmp(&m, &before, sizeof m) != 0;
}

static void c_units_scale(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_units_scale(PD_UNITS_MM) == 0.001 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_units_parse(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_units u = (pd_units)77;
    o->st = pd_units_parse(P(0, "mm"), P(1, &u));
    o->touched = o->st != PD_OK && u != (pd_units)77;
}

static void c_units_plausible(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_units u = (pd_units)77;
    /* 40 m read as metres: not plausible, millimetres suggested. */
    int r = pd_units_plausible(40.0, PD_UNITS_M, P(0, &u));
    o->st = r == 0 && (k == 0 || u == PD_UNITS_MM) ? PD_OK : PD_ERR_INTERNAL;
}

DEFAULTS(mesh_read_options_default, pd_mesh_read_options)

static void c_mesh_read(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_mesh_read_options r;
    pd_mesh_read_options_default(&r);
    pd_mesh *m = SENTINEL;
    o->st = pd_mesh_read(P(0, CUBE), P(1, &r), P(2, &m), P(3, &o->diag));
    settle_output(o, m, pd_mesh_free);
}

static void c_mesh_parse(const fixture *f, int k, outcome *o)
{
    (void)f;
    static const char off[] = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
                              "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    pd_mesh_read_options r;
    pd_mesh_read_options_default(&r);
    pd_mesh *m = SENTINEL;
    o->st = pd_mesh_parse(P(0, off), sizeof off - 1, P(1, "t.off"), P(2, &r), P(3, &m),
                          P(4, &o->diag));
    settle_output(o, m, pd_mesh_free);
}

static void c_mesh_clone(const fixture *f, int k, outcome *o)
{
    pd_mesh *m = pd_mesh_clone(P(0, f->mesh));
    o->st = m ? PD_OK : PD_ERR_USAGE;
    pd_mesh_free(m);
}

static void c_mesh_weld(const fixture *f, int k, outcome *o)
{
    pd_mesh *m = pd_mesh_clone(f->mesh);
    int n = -7;
    o->st = m ? pd_mesh_weld(P(0, m), 1e-9, P(1, &n)) : PD_ERR_NOMEM;
    o->touched = o->st != PD_OK && n != -7;
    pd_mesh_free(m);
}

static void c_mesh_orient(const fixture *f, int k, outcome *o)
{
    pd_mesh *m = pd_mesh_clone(f->mesh);
    int n = -7;
    o->st = m ? pd_mesh_orient(P(0, m), P(1, &n), P(2, &o->diag)) : PD_ERR_NOMEM;
    o->touched = o->st != PD_OK && n != -7;
    pd_mesh_free(m);
}

static void c_mesh_size(const fixture *f, int k, outcome *o)
{
    double s = pd_mesh_size(P(0, f->mesh));
    o->st = s > 0 ? PD_OK : s == 0 ? PD_ERR_USAGE : PD_ERR_INTERNAL;
}

static void c_mesh_free(const fixture *f, int k, outcome *o)
{
    pd_mesh *m = pd_mesh_clone(f->mesh);
    free_unless_null(k, m, pd_mesh_free);
    o->st = PD_OK;
}

DEFAULTS(part_options_default, pd_part_options)

static void c_part_build(const fixture *f, int k, outcome *o)
{
    pd_part_options po;
    pd_part_options_default(&po);
    pd_part *p = SENTINEL;
    o->st = pd_part_build(P(0, f->mesh), P(1, &po), P(2, &p), P(3, &o->diag));
    settle_output(o, p, pd_part_free);
}

static void c_part_build_take(const fixture *f, int k, outcome *o)
{
    pd_part_options po;
    pd_part_options_default(&po);
    pd_part *p = SENTINEL;
    pd_mesh *m = pd_mesh_clone(f->mesh);
    o->st = pd_part_build_take(P(0, &m), P(1, &po), P(2, &p), P(3, &o->diag));
    /* Taken whatever the outcome, unless the pointer to it was NULL. */
    if (k != 0 && m != NULL)
        o->st = PD_ERR_INTERNAL;
    pd_mesh_free(m);
    settle_output(o, p, pd_part_free);
}

static void c_part_free(const fixture *f, int k, outcome *o)
{
    pd_part *p = NULL;
    o->st = pd_part_build(f->mesh, NULL, &p, NULL);
    free_unless_null(k, p, pd_part_free);
}

static void c_contact_time_auto(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_contact_time_auto(0.01) > 0 ? PD_OK : PD_ERR_INTERNAL;
}

DEFAULTS(scene_default, pd_scene)

static void c_scene_set(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_scene s, before;
    pd_scene_default(&s);
    before = s;
    o->st = pd_scene_set(P(0, &s), P(1, "mu"), P(2, "0.5"), P(3, &o->diag));
    o->touched = o->st != PD_OK && memcmp(&s, &before, sizeof s) != 0;
}

static void c_scene_read(const fixture *f, int k, outcome *o)
{
    pd_scene s, before;
    pd_scene_default(&s);
    before = s;
    o->st = pd_scene_read(P(0, f->scene_path), P(1, &s), P(2, &o->diag));
    o->touched = o->st != PD_OK && memcmp(&s, &before, sizeof s) != 0;
}

static void c_scene_check(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_scene s;
    pd_scene_default(&s);
    o->st = pd_scene_check(P(0, &s), P(1, &o->diag));
}

DEFAULTS(sim_options_default, pd_sim_options)

static void c_sim_options_check(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_sim_options so;
    pd_sim_options_default(&so);
    o->st = pd_sim_options_check(P(0, &so), P(1, &o->diag));
}

static void c_engine_available(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_engine_available(PD_ENGINE_ODE) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_engine_register(const fixture *f, int k, outcome *o)
{
    (void)f;
    o->st = pd_engine_register(PD_ENGINE_BULLET, P(0, &pd_engine_bullet), P(1, PD_VERSION_STRING));
}

static void c_shard_of(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_shard_of(7, 3) == 1 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_shard_drops(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_shard_drops(10, 0, 3) == 4 ? PD_OK : PD_ERR_INTERNAL;
}

/* Options NULL means the default 2000 drops: on the cube they take well
 * under a second. */
static void few_drops(pd_sim_options *so)
{
    pd_sim_options_default(so);
    so->ndrops = 20;
    so->threads = 1;
}

static void c_sim_run(const fixture *f, int k, outcome *o)
{
    pd_scene sc;
    pd_scene_default(&sc);
    pd_sim_options so;
    few_drops(&so);
    pd_sim_result *r = SENTINEL;
    o->st = pd_sim_run(P(0, f->part), P(1, f->res), P(2, &sc), P(3, &so), P(4, &r),
                       P(5, &o->diag));
    settle_output(o, r, pd_sim_result_free);
}

/* A fresh sum for the whole run f->sim is a shard of (nshards ignored). */
static pd_sim_result *new_sum(const fixture *f)
{
    pd_sim_options so;
    few_drops(&so);
    pd_sim_result *r = NULL;
    if (pd_sim_result_new(f->res, NULL, &so, &r, NULL) != PD_OK)
        return NULL;
    return r;
}

static void c_sim_result_free(const fixture *f, int k, outcome *o)
{
    pd_sim_result *r = new_sum(f);
    o->st = r ? PD_OK : PD_ERR_INTERNAL;
    free_unless_null(k, r, pd_sim_result_free);
}

static void c_sim_result_new(const fixture *f, int k, outcome *o)
{
    pd_scene sc;
    pd_scene_default(&sc);
    pd_sim_options so;
    few_drops(&so);
    pd_sim_result *r = SENTINEL;
    o->st = pd_sim_result_new(P(0, f->res), P(1, &sc), P(2, &so), P(3, &r), P(4, &o->diag));
    settle_output(o, r, pd_sim_result_free);
}

static void c_sim_result_add(const fixture *f, int k, outcome *o)
{
    pd_sim_result *sum = new_sum(f);
    long n0 = sum ? sum->n : -1;
    o->st = sum ? pd_sim_result_add(P(0, sum), P(1, f->sim), P(2, &o->diag)) : PD_ERR_INTERNAL;
    o->touched = o->st != PD_OK && sum && sum->n != n0;
    pd_sim_result_free(sum);
}

static void c_sim_result_finish(const fixture *f, int k, outcome *o)
{
    pd_sim_result *sum = new_sum(f);
    o->st = sum ? pd_sim_result_finish(P(0, sum), P(1, &o->diag)) : PD_ERR_INTERNAL;
    pd_sim_result_free(sum);
}

DEFAULTS(static_options_default, pd_static_options)

static void c_static_options_check(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_static_options so;
    pd_static_options_default(&so);
    o->st = pd_static_options_check(P(0, &so), P(1, &o->diag));
}

static void c_static_estimate(const fixture *f, int k, outcome *o)
{
    pd_static_options so;
    pd_static_options_default(&so);
    pd_static_result *r = SENTINEL;
    o->st = pd_static_estimate(P(0, f->part), P(1, &so), P(2, &r), P(3, &o->diag));
    settle_output(o, r, pd_static_result_free);
}

static void c_static_result_free(const fixture *f, int k, outcome *o)
{
    pd_static_result *r = NULL;
    o->st = pd_static_estimate(f->part, NULL, &r, NULL);
    free_unless_null(k, r, pd_static_result_free);
}

static void c_pose_transform(const fixture *f, int k, outcome *o)
{
    double t[16], before[16];
    memset(t, 0x5a, sizeof t);
    memcpy(before, t, sizeof t);
    o->st = pd_pose_transform(P(0, f->part), P(1, &f->res->poses[0]), P(2, t), P(3, &o->diag));
    o->touched = o->st != PD_OK && memcmp(t, before, sizeof t) != 0;
}

static void c_solid_angle_triangle(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    pd_vec3 a = {1, 0, 0}, b = {0, 1, 0}, c = {0, 0, 1};
    o->st = pd_solid_angle_triangle(a, b, c) > 0 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_status_str(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_status_str(PD_ERR_USAGE) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_status_is_input_error(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_status_is_input_error(PD_ERR_USAGE) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_symmetry_find(const fixture *f, int k, outcome *o)
{
    pd_symmetry *s = SENTINEL;
    o->st = pd_symmetry_find(P(0, f->part), P(1, &s), P(2, &o->diag));
    settle_output(o, s, pd_symmetry_free);
}

static void c_symmetry_free(const fixture *f, int k, outcome *o)
{
    pd_symmetry *s = NULL;
    o->st = pd_symmetry_find(f->part, &s, NULL);
    free_unless_null(k, s, pd_symmetry_free);
}

static void c_pose_classes(const fixture *f, int k, outcome *o)
{
    int cls[64], n = -7;
    for (int i = 0; i < 64; i++)
        cls[i] = -7;
    o->st = f->res->nposes <= 64 ? pd_pose_classes(P(0, f->part), P(1, f->res), P(2, cls),
                                                   P(3, &n), P(4, &o->diag))
                                 : PD_ERR_INTERNAL;
    o->touched = o->st != PD_OK && (n != -7 || cls[0] != -7);
}

static void c_sim_result_grouped(const fixture *f, int k, outcome *o)
{
    pd_sim_result *g = SENTINEL;
    o->st = pd_sim_result_grouped(P(0, f->sim), P(1, f->class_of), f->nclasses, P(2, &g),
                                  P(3, &o->diag));
    settle_output(o, g, pd_sim_result_free);
}

DEFAULTS(fit_options_default, pd_fit_options)

/* A fit of the cube's restitution to ten drops on its one class: a few
 * evaluations of ten drops. */
static pd_status cube_fit(const fixture *f, int k, pd_fit_result **r, pd_diag *diag)
{
    static const long count[1] = {10};
    pd_fit_part part = {f->part, f->res, f->class_of, f->nclasses, count, NULL, 0};
    pd_fit_param param = {"restitution", 0.1, 0.5, 0, 0};
    pd_fit_options fo;
    pd_fit_options_default(&fo);
    fo.ndrops = 10;
    fo.threads = 1;
    fo.max_evals = 2;
    fo.npoints = 1;
    pd_scene sc;
    pd_scene_default(&sc);
    return pd_fit_run(P(0, &part), 1, P(1, &param), 1, P(2, &sc), P(3, &fo), P(4, r), P(5, diag));
}

static void c_fit_run(const fixture *f, int k, outcome *o)
{
    pd_fit_result *r = SENTINEL;
    o->st = cube_fit(f, k, &r, &o->diag);
    settle_output(o, r, pd_fit_result_free);
}

static void c_fit_result_free(const fixture *f, int k, outcome *o)
{
    pd_fit_result *r = NULL;
    o->st = cube_fit(f, -1, &r, NULL);
    free_unless_null(k, r, pd_fit_result_free);
}

static void c_fit_smooth(const fixture *f, int k, outcome *o)
{
    (void)f;
    const double p[2] = {0.5, 0.5};
    double out[2] = {-7, -7};
    pd_fit_smooth(2, P(0, p), 10, 0.5, P(1, out));
    o->st = k < 0 && out[0] != 0.5 ? PD_ERR_INTERNAL : PD_OK;
}

static void c_fit_loglik(const fixture *f, int k, outcome *o)
{
    (void)f;
    const double p[2] = {0.5, 0.5};
    const long c[2] = {1, 1};
    double l = pd_fit_loglik(2, P(0, c), P(1, p), 10, 0.5);
    o->st = (k < 0 ? l < 0 : l == 0) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_fit_loglik_dm(const fixture *f, int k, outcome *o)
{
    (void)f;
    const double p[2] = {0.5, 0.5};
    const long c[2] = {1, 1};
    double l = pd_fit_loglik_dm(2, P(0, c), P(1, p), 10, 0.5);
    o->st = (k < 0 ? l < 0 : l == 0) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_version(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_version() ? PD_OK : PD_ERR_INTERNAL;
}

static void c_first_order_index(const fixture *f, int k, outcome *o)
{
    (void)f;
    double x[8] = {1, 2, 3, 4, 5, 6, 7, 8}, y[8] = {0, 1, 0, 1, 1, 1, 0, 1};
    double s = -7, lo = -7, hi = -7;
    o->st = pd_first_order_index(P(0, x), P(1, y), 8, 1, P(2, &s), P(3, &lo), P(4, &hi),
                                 P(5, &o->diag));
    o->touched = o->st != PD_OK && (s != -7 || lo != -7 || hi != -7);
}

/* A run with its trial records, which pd_sim_sensitivity reads. */
static pd_sim_result *recorded_run(const fixture *f)
{
    pd_sim_options so;
    few_drops(&so);
    so.keep_trials = 1;
    pd_sim_result *r = NULL;
    return pd_sim_run(f->part, f->res, NULL, &so, &r, NULL) == PD_OK ? r : NULL;
}

static void c_sim_sensitivity(const fixture *f, int k, outcome *o)
{
    pd_sim_result *r = recorded_run(f);
    pd_scene sc;
    pd_scene_default(&sc);
    pd_sensitivity *s = SENTINEL;
    o->st = r ? pd_sim_sensitivity(P(0, r), P(1, &sc), f->part->size, P(2, f->class_of),
                                   f->nclasses, P(3, &s), P(4, &o->diag))
              : PD_ERR_INTERNAL;
    settle_output(o, s, pd_sensitivity_free);
    pd_sim_result_free(r);
}

static void c_sensitivity_free(const fixture *f, int k, outcome *o)
{
    pd_sim_result *r = recorded_run(f);
    pd_scene sc;
    pd_scene_default(&sc);
    pd_sensitivity *s = NULL;
    o->st = r ? pd_sim_sensitivity(r, &sc, f->part->size, NULL, 0, &s, NULL) : PD_ERR_INTERNAL;
    free_unless_null(k, s, pd_sensitivity_free);
    pd_sim_result_free(r);
}

static const pd_change cube_change = {PD_CHANGE_SCALE, 2, 0, 0.0, 0.0, 0.5, 2.0};

static void c_design_axes(const fixture *f, int k, outcome *o)
{
    pd_vec3 axes[3] = {{-7, -7, -7}, {-7, -7, -7}, {-7, -7, -7}};
    o->st = pd_design_axes(P(0, f->part), P(1, axes), P(2, &o->diag));
    o->touched = o->st != PD_OK && axes[0].x != -7;
}

static void c_design_apply(const fixture *f, int k, outcome *o)
{
    double v = 1.5;
    pd_part *p = SENTINEL;
    o->st = pd_design_apply(P(0, f->part), P(1, &cube_change), 1, P(2, &v), P(3, &p),
                            P(4, &o->diag));
    settle_output(o, p, pd_part_free);
}

static void c_design_sensitivity(const fixture *f, int k, outcome *o)
{
    pd_sim_options so;
    few_drops(&so);
    pd_design_sens *s = SENTINEL;
    o->st = pd_design_sensitivity(P(0, f->part), P(1, f->res), P(2, (const pd_static_options *)NULL),
                                  P(3, &cube_change), 1, P(4, f->class_of), f->nclasses,
                                  P(5, (const pd_scene *)NULL), P(6, &so), P(7, &s), P(8, &o->diag));
    settle_output(o, s, pd_design_sens_free);
}

static void c_design_sens_free(const fixture *f, int k, outcome *o)
{
    pd_design_sens *s = NULL;
    o->st = pd_design_sensitivity(f->part, f->res, NULL, &cube_change, 1, NULL, 0, NULL, NULL, &s,
                                  NULL);
    free_unless_null(k, s, pd_design_sens_free);
}

DEFAULTS(design_options_default, pd_design_options)

static pd_status cube_design(const fixture *f, int k, pd_design_result **r, pd_diag *diag)
{
    pd_design_options o;
    pd_design_options_default(&o);
    o.sim.ndrops = 0;
    o.check_drops = 0;
    pd_design_target t = {{0, 0, 1}, 0.3};
    return pd_design_run(P(0, f->part), P(1, &cube_change), 1, PD_GOAL_TARGET, P(2, &t), 1,
                         P(3, &o), P(4, r), P(5, diag));
}

static void c_design_run(const fixture *f, int k, outcome *o)
{
    pd_design_result *r = SENTINEL;
    o->st = cube_design(f, k, &r, &o->diag);
    settle_output(o, r, pd_design_result_free);
}

static void c_design_result_free(const fixture *f, int k, outcome *o)
{
    pd_design_result *r = NULL;
    o->st = cube_design(f, -1, &r, NULL);
    free_unless_null(k, r, pd_design_result_free);
}

static void c_scene_param_name(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_scene_param_name(PD_PARAM_MU) ? PD_OK : PD_ERR_INTERNAL;
}

/* The scene's read-only helpers take a NULL scene as no scene: an empty
 * text, no range, the middle quantile, the default scene's time limit;
 * the draw does nothing without a scene or somewhere to put its values. */
static void c_scene_format(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_scene sc;
    pd_scene_default(&sc);
    char buf[64];
    pd_scene_format(P(0, &sc), PD_PARAM_MU, P(1, buf), sizeof buf);
    o->st = PD_OK;
}

static void c_scene_ranged(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_scene sc;
    pd_scene_default(&sc);
    o->st = pd_scene_ranged(P(0, &sc)) == 0 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_scene_varies(const fixture *f, int k, outcome *o)
{
    (void)f;
    pd_scene sc;
    pd_scene_default(&sc);
    o->st = pd_scene_varies(P(0, &sc), PD_PARAM_MU) == 0 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_scene_draw(const fixture *f, int k, outcome *o)
{
    pd_scene sc, drawn;
    pd_scene_default(&sc);
    double values[PD_NPARAMS];
    pd_scene_draw(P(0, &sc), f->part->size, 1, 3, P(1, values), P(2, &drawn));
    o->st = PD_OK;
}

static void c_scene_quantile(const fixture *f, int k, outcome *o)
{
    pd_scene sc;
    pd_scene_default(&sc);
    o->st = pd_scene_quantile(P(0, &sc), PD_PARAM_MU, f->part->size, 0.3) == 0.5 ? PD_OK
                                                                              : PD_ERR_INTERNAL;
}

static void c_drop_stage_name(const fixture *f, int k, outcome *o)
{
    (void)f, (void)k;
    o->st = pd_drop_stage_name(PD_STAGE_NONE) ? PD_OK : PD_ERR_INTERNAL;
}

static void c_time_limit_auto(const fixture *f, int k, outcome *o)
{
    pd_scene sc;
    pd_scene_default(&sc);
    o->st = pd_time_limit_auto(f->part->size, P(0, &sc)) > 0 ? PD_OK : PD_ERR_INTERNAL;
}

/* A duration or length of the part, 0 for no part. */
static void c_contact_time_auto_part(const fixture *f, int k, outcome *o)
{
    double t = pd_contact_time_auto_part(P(0, f->part));
    o->st = k == 0 ? (t == 0.0 ? PD_OK : PD_ERR_INTERNAL) : t > 0 ? PD_OK : PD_ERR_INTERNAL;
}

static void c_contact_time_auto_size(const fixture *f, int k, outcome *o)
{
    double l = pd_contact_time_auto_size(P(0, f->part));
    o->st = k == 0 ? (l == 0.0 ? PD_OK : PD_ERR_INTERNAL) : l > 0 ? PD_OK : PD_ERR_INTERNAL;
}

/* --- the table ------------------------------------------------------------- */

typedef struct {
    const char *name;
    const char *pointers; /* pointer parameters by name, '?' where NULL is allowed */
    void (*call)(const fixture *f, int k, outcome *o);
} entry;

static const entry table[] = {
    {"pd_bullet_register", "", c_bullet_register},
    {"pd_diag_init", "?diag", c_diag_init},
    {"pd_hull_build", "pts hull ?diag", c_hull_build},
    {"pd_hull_check", "hull ?pts ?diag", c_hull_check},
    {"pd_hull_free", "?hull", c_hull_free},
    {"pd_mass_compute", "mesh mass ?diag", c_mass_compute},
    {"pd_units_scale", "", c_units_scale},
    {"pd_units_parse", "text units", c_units_parse},
    {"pd_units_plausible", "?suggest", c_units_plausible},
    {"pd_mesh_read_options_default", "?options", c_mesh_read_options_default},
    {"pd_mesh_read", "path ?options mesh ?diag", c_mesh_read},
    {"pd_mesh_parse", "data ?name ?options mesh ?diag", c_mesh_parse},
    {"pd_mesh_clone", "mesh", c_mesh_clone},
    {"pd_mesh_weld", "mesh ?nmerged", c_mesh_weld},
    {"pd_mesh_orient", "mesh ?nflipped ?diag", c_mesh_orient},
    {"pd_mesh_size", "mesh", c_mesh_size},
    {"pd_mesh_free", "?mesh", c_mesh_free},
    {"pd_part_options_default", "?options", c_part_options_default},
    {"pd_part_build", "mesh ?options part ?diag", c_part_build},
    {"pd_part_build_take", "mesh ?options part ?diag", c_part_build_take},
    {"pd_part_free", "?part", c_part_free},
    {"pd_contact_time_auto", "", c_contact_time_auto},
    {"pd_scene_default", "?scene", c_scene_default},
    {"pd_scene_set", "scene key value ?diag", c_scene_set},
    {"pd_scene_read", "path scene ?diag", c_scene_read},
    {"pd_scene_check", "scene ?diag", c_scene_check},
    {"pd_sim_options_default", "?options", c_sim_options_default},
    {"pd_sim_options_check", "options ?diag", c_sim_options_check},
    {"pd_engine_available", "", c_engine_available},
    {"pd_engine_register", "engine version", c_engine_register},
    {"pd_shard_of", "", c_shard_of},
    {"pd_shard_drops", "", c_shard_drops},
    {"pd_sim_run", "part static_result ?scene ?options result ?diag", c_sim_run},
    {"pd_sim_result_free", "?result", c_sim_result_free},
    {"pd_sim_result_new", "static_result ?scene ?options result ?diag", c_sim_result_new},
    {"pd_sim_result_add", "sum shard ?diag", c_sim_result_add},
    {"pd_sim_result_finish", "result ?diag", c_sim_result_finish},
    {"pd_static_options_default", "?options", c_static_options_default},
    {"pd_static_options_check", "options ?diag", c_static_options_check},
    {"pd_static_estimate", "part ?options result ?diag", c_static_estimate},
    {"pd_static_result_free", "?result", c_static_result_free},
    {"pd_pose_transform", "part pose transform ?diag", c_pose_transform},
    {"pd_solid_angle_triangle", "", c_solid_angle_triangle},
    {"pd_status_str", "", c_status_str},
    {"pd_status_is_input_error", "", c_status_is_input_error},
    {"pd_symmetry_find", "part symmetry ?diag", c_symmetry_find},
    {"pd_symmetry_free", "?symmetry", c_symmetry_free},
    {"pd_pose_classes", "part res class_of nclasses ?diag", c_pose_classes},
    {"pd_sim_result_grouped", "sim class_of grouped ?diag", c_sim_result_grouped},
    {"pd_version", "", c_version},
    {"pd_fit_options_default", "?options", c_fit_options_default},
    {"pd_fit_run", "parts params ?base options result ?diag", c_fit_run},
    {"pd_fit_result_free", "?result", c_fit_result_free},
    {"pd_fit_smooth", "?p_sim ?out", c_fit_smooth},
    {"pd_fit_loglik", "?count ?p_sim", c_fit_loglik},
    {"pd_fit_loglik_dm", "?count ?p_sim", c_fit_loglik_dm},
    {"pd_first_order_index", "x y index lo hi ?diag", c_first_order_index},
    {"pd_sim_sensitivity", "result scene ?class_of out ?diag", c_sim_sensitivity},
    {"pd_sensitivity_free", "?sensitivity", c_sensitivity_free},
    {"pd_design_axes", "part axes ?diag", c_design_axes},
    {"pd_design_apply", "part changes value changed ?diag", c_design_apply},
    {"pd_design_sensitivity", "part res ?options changes ?class_of ?scene ?sim out ?diag",
     c_design_sensitivity},
    {"pd_design_sens_free", "?sensitivity", c_design_sens_free},
    {"pd_design_options_default", "?options", c_design_options_default},
    {"pd_design_run", "part changes targets options result ?diag", c_design_run},
    {"pd_design_result_free", "?result", c_design_result_free},
    {"pd_scene_param_name", "", c_scene_param_name},
    {"pd_scene_format", "?scene ?buf", c_scene_format},
    {"pd_scene_ranged", "?scene", c_scene_ranged},
    {"pd_scene_varies", "?scene", c_scene_varies},
    {"pd_scene_draw", "?scene ?values ?drawn", c_scene_draw},
    {"pd_scene_quantile", "?scene", c_scene_quantile},
    {"pd_drop_stage_name", "", c_drop_stage_name},
    {"pd_time_limit_auto", "?scene", c_time_limit_auto},
    {"pd_contact_time_auto_part", "?part", c_contact_time_auto_part},
    {"pd_contact_time_auto_size", "?part", c_contact_time_auto_size},
};
enum { NTABLE = sizeof table / sizeof table[0] };

/* The i-th word of a space-separated list into out (without its '?'); its
 * '?' flag, or -1 when there is no such word. */
static int word_at(const char *list, int i, char *out, size_t size)
{
    for (int n = 0;; n++) {
        while (*list == ' ')
            list++;
        if (!*list)
            return -1;
        const char *e = list;
        while (*e && *e != ' ')
            e++;
        if (n == i) {
            int optional = *list == '?';
            size_t len = (size_t)(e - list) - (size_t)optional;
            snprintf(out, size, "%.*s", (int)(len < size ? len : size - 1), list + optional);
            return optional;
        }
        list = e;
    }
}

/* --- the headers' declarations ------------------------------------------- */

/* text with comments and preprocessor lines blanked out. */
static void strip(char *text)
{
    for (char *p = text; *p; p++) {
        if (p[0] == '/' && p[1] == '*') {
            char *e = strstr(p + 2, "*/");
            char *end = e ? e + 2 : p + strlen(p);
            memset(p, ' ', (size_t)(end - p));
            p = end - 1;
        } else if (p[0] == '/' && p[1] == '/') {
            while (*p && *p != '\n')
                *p++ = ' ';
            p--;
        } else if (*p == '#' && (p == text || p[-1] == '\n')) {
            /* A directive, with its continuation lines. */
            while (*p && !(*p == '\n' && p[-1] != '\\'))
                *p++ = ' ';
            p--;
        }
    }
}

/* The last identifier in [s, e): a parameter's name. */
static void last_identifier(const char *s, const char *e, char *out, size_t size)
{
    while (e > s && !(isalnum((unsigned char)e[-1]) || e[-1] == '_'))
        e--;
    const char *b = e;
    while (b > s && (isalnum((unsigned char)b[-1]) || b[-1] == '_'))
        b--;
    snprintf(out, size, "%.*s", (int)(e - b), b);
}

typedef struct {
    char name[64];
    char pointers[256]; /* pointer parameter names, space-separated */
} declaration;

/* Appends to decl (room for max) the PD_API functions declared in text. */
static int parse_declarations(char *text, declaration *decl, int n, int max)
{
    strip(text);
    for (char *p = strstr(text, "PD_API"); p; p = strstr(p + 6, "PD_API")) {
        char *open = strchr(p, '('), *semi = strchr(p, ';');
        if (!open || !semi || open > semi || n == max) {
            CHECK(open && semi && open < semi && n < max);
            continue;
        }
        declaration *d = &decl[n++];
        last_identifier(p, open, d->name, sizeof d->name);
        d->pointers[0] = '\0';
        /* The parenthesis that closes the parameter list. */
        char *close = open + 1;
        for (int depth = 1; close < semi && (depth += *close == '(' ? 1 : *close == ')' ? -1 : 0) > 0;)
            close++;
        CHECK(close < semi);
        for (char *q = open + 1, *c; close < semi; q = c + 1) {
            int depth = 0;
            for (c = q; c < close && (depth > 0 || *c != ','); c++)
                depth += *c == '(' ? 1 : *c == ')' ? -1 : 0;
            const char *bracket = memchr(q, '[', (size_t)(c - q));
            if (memchr(q, '*', (size_t)(c - q)) || bracket) {
                /* The name comes before an array's bounds. */
                char param[64];
                last_identifier(q, bracket ? bracket : c, param, sizeof param);
                size_t len = strlen(d->pointers);
                snprintf(d->pointers + len, sizeof d->pointers - len, "%s%s", len ? " " : "",
                         param);
            }
            if (c >= close)
                break;
        }
    }
    return n;
}

static int read_headers(declaration *decl, int max)
{
    DIR *dir = opendir(HEADERS);
    CHECK(dir != NULL);
    if (!dir)
        return 0;
    int n = 0, nfiles = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 3 || strcmp(e->d_name + len - 2, ".h") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", HEADERS, e->d_name);
        char *text = slurp(path);
        CHECK(text != NULL);
        if (text)
            n = parse_declarations(text, decl, n, max);
        free(text);
        nfiles++;
    }
    closedir(dir);
    pd_note("nullargs: %d PD_API functions in %d headers, %d in the table\n", n, nfiles,
            (int)NTABLE);
    return n;
}

/* The table's pointer names without the '?' marks. */
static void table_pointers(const entry *e, char *out, size_t size)
{
    char w[64];
    out[0] = '\0';
    for (int i = 0; word_at(e->pointers, i, w, sizeof w) >= 0; i++) {
        size_t len = strlen(out);
        snprintf(out + len, size - len, "%s%s", len ? " " : "", w);
    }
}

static void test_table_matches_headers(void)
{
    static declaration decl[256];
    int n = read_headers(decl, 256);
    CHECK(n >= 40); /* the parser found the API (44 functions when written) */
    for (int i = 0; i < n; i++) {
        const entry *e = NULL;
        for (int t = 0; t < NTABLE && !e; t++)
            if (strcmp(table[t].name, decl[i].name) == 0)
                e = &table[t];
        if (!e) {
            printf("     %s is declared PD_API but not in the table of %s\n", decl[i].name,
                   __FILE__);
            CHECK(e != NULL);
            continue;
        }
        char ptrs[256];
        table_pointers(e, ptrs, sizeof ptrs);
        if (strcmp(ptrs, decl[i].pointers) != 0)
            printf("     %s: the header's pointer parameters are '%s', the table's '%s'\n",
                   decl[i].name, decl[i].pointers, ptrs);
        CHECK(strcmp(ptrs, decl[i].pointers) == 0);
    }
    for (int t = 0; t < NTABLE; t++) {
        int found = 0;
        for (int i = 0; i < n && !found; i++)
            found = strcmp(table[t].name, decl[i].name) == 0;
        if (!found)
            printf("     %s is in the table but no header declares it\n", table[t].name);
        CHECK(found);
    }
}

/* --- the calls --------------------------------------------------------------- */

/* Runs one call in a child process, so that a crash (or a sanitizer's
 * abort) is reported with the function and argument that caused it and the
 * other calls still run. 0 if the child did not come back with an outcome. */
static int run_isolated(const entry *e, const fixture *f, int k, outcome *o, int *sig)
{
    int fd[2];
    *sig = 0;
    if (pipe(fd) != 0)
        return 0;
    fflush(stdout);
    pid_t pid = fork();
    if (pid < 0) {
        close(fd[0]);
        close(fd[1]);
        return 0;
    }
    if (pid == 0) {
        close(fd[0]);
        clear(o);
        e->call(f, k, o);
        ssize_t w = write(fd[1], o, sizeof *o);
        _exit(w == (ssize_t)sizeof *o ? 0 : 1);
    }
    close(fd[1]);
    ssize_t got = 0, r;
    while (got < (ssize_t)sizeof *o &&
           (r = read(fd[0], (char *)o + got, sizeof *o - (size_t)got)) > 0)
        got += r;
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status))
        *sig = WTERMSIG(status);
    return got == (ssize_t)sizeof *o && WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

static void test_calls(const fixture *f)
{
    int ncalls = 0;
    for (int t = 0; t < NTABLE; t++) {
        const entry *e = &table[t];
        char param[64];
        int has_diag = strstr(e->pointers, "diag") != NULL;
        outcome base;
        int sig;
        if (!run_isolated(e, f, -1, &base, &sig)) {
            printf("     %s with every argument given: crashed (signal %d)\n", e->name, sig);
            CHECK(!"the call came back");
            continue;
        }
        if (base.st != PD_OK)
            printf("     %s with every argument given: %s: %s\n", e->name,
                   pd_status_str(base.st), base.diag.message);
        CHECK_STATUS(base.st, PD_OK);
        for (int k = 0;; k++) {
            int optional = word_at(e->pointers, k, param, sizeof param);
            if (optional < 0)
                break;
            outcome o;
            ncalls++;
            if (!run_isolated(e, f, k, &o, &sig)) {
                printf("     %s with %s NULL: crashed (signal %d)\n", e->name, param, sig);
                CHECK(!"the call came back");
                continue;
            }
            pd_status want = optional ? PD_OK : PD_ERR_USAGE;
            int message = optional || !has_diag || strcmp(param, "diag") == 0 ||
                          o.diag.message[0] != '\0';
            if (o.st != want || o.touched || !message)
                printf("     %s with %s NULL: %s (expected %s)%s%s, message '%s'\n", e->name,
                       param, pd_status_str(o.st), pd_status_str(want),
                       o.touched ? ", an output written" : "", message ? "" : ", no message",
                       o.diag.message);
            CHECK_STATUS(o.st, want);
            CHECK(!o.touched);
            CHECK(message);
        }
    }
    pd_note("nullargs: %d calls with one NULL argument\n", ncalls);
}

/* --- fixture ------------------------------------------------------------------ */

static int setup(fixture *f)
{
    memset(f, 0, sizeof *f);
    f->mesh = mesh_box(0.01, 0.01, 0.01);
    pd_sim_options so;
    few_drops(&so);
    int ok = f->mesh && pd_part_build(f->mesh, NULL, &f->part, NULL) == PD_OK &&
             pd_static_estimate(f->part, NULL, &f->res, NULL) == PD_OK &&
             pd_sim_run(f->part, f->res, NULL, &so, &f->sim, NULL) == PD_OK;
    if (ok) {
        f->class_of = malloc(sizeof *f->class_of * (size_t)f->res->nposes);
        ok = f->class_of &&
             pd_pose_classes(f->part, f->res, f->class_of, &f->nclasses, NULL) == PD_OK;
    }
    snprintf(f->scene_path, sizeof f->scene_path, "/tmp/posedrop-nullargs-XXXXXX");
    int fd = ok ? mkstemp(f->scene_path) : -1;
    ok = ok && fd >= 0 && write(fd, "mu = 0.4\n", 9) == 9;
    if (fd >= 0)
        close(fd);
    else
        f->scene_path[0] = '\0';
    CHECK(ok);
    return ok;
}

static void teardown(fixture *f)
{
    if (f->scene_path[0])
        unlink(f->scene_path);
    free(f->class_of);
    pd_sim_result_free(f->sim);
    pd_static_result_free(f->res);
    pd_part_free(f->part);
    pd_mesh_free(f->mesh);
}

void suite_nullargs(void)
{
    test_table_matches_headers();
    fixture f;
    if (setup(&f))
        test_calls(&f);
    teardown(&f);
}
