/* cli.c: the posedrop command, a thin client of libposedrop.
 *
 * It only parses arguments, calls the library and prints: the results as CSV
 * on stdout, diagnostics on stderr. Exit codes: 0 success, 2 bad usage or
 * input (nothing is printed on stdout), 1 internal failure, 130 or 143
 * interrupted by SIGINT or SIGTERM (what was done is printed, marked
 * partial). */
#include <errno.h>
#include <float.h>
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>
#include "base/number.h" /* one reading of numbers, shared with scene files */
#include "cli/cli.h"

const char *prog = "posedrop";

static void print_warning(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "%s: warning: %s\n", prog, message);
}

/* Axis-aligned normals come out with round-off components like 1e-17; print
 * them as 0 (and never as -0) so the CSV is stable and readable. */
static double clean(double x)
{
    return fabs(x) < PD_PRINT_ZERO ? 0.0 : x;
}

double cli_clean(double x)
{
    return clean(x);
}

/* A stationary shard adds the counts its merge needs to estimate the chain:
 * first (uniform drops settled in the row's pose) and to_J (drops started
 * resting on the row's pose that settled in pose J). */
static void print_poses(const pd_static_result *res, const pd_sim_result *sim)
{
    int chain = sim && sim->nshards > 0 && sim->transitions;
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs%s%s",
           sim ? ",n,count,p,ci_lo,ci_hi,unsettled,partial" : "", chain ? ",first" : "");
    for (int j = 0; chain && j < res->nposes; j++)
        printf(",to_%d", j + 1);
    printf("\n");
    for (int i = 0; i < res->nposes; i++) {
        const pd_pose *p = &res->poses[i];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", i + 1, clean(p->normal.x),
               clean(p->normal.y), clean(p->normal.z), p->area, p->height, clean(p->p_qs),
               clean(p->p_pqs));
        if (sim)
            printf(",%ld,%ld,%.10g,%.10g,%.10g,%ld,%d", sim->n, sim->count[i], sim->p[i],
                   sim->ci_lo[i], sim->ci_hi[i], sim->unsettled, sim->partial);
        for (int j = -1; chain && j < res->nposes; j++)
            printf(",%ld", j < 0 ? sim->first_count[i]
                                 : sim->transitions[(size_t)i * (size_t)res->nposes + (size_t)j]);
        printf("\n");
    }
}

/* One row per class: the columns of print_poses, the first member's geometry,
 * probabilities summed (gsim holds the library's grouped counts and
 * intervals), and the members' pose numbers. */
static void print_classes(const pd_static_result *res, const pd_sim_result *gsim,
                          const int *class_of, int nclasses)
{
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs%s,members\n",
           gsim ? ",n,count,p,ci_lo,ci_hi,unsettled,partial" : "");
    for (int c = 0; c < nclasses; c++) {
        int first = -1;
        double qs = 0.0, pqs = 0.0;
        for (int i = 0; i < res->nposes; i++)
            if (class_of[i] == c) {
                if (first < 0)
                    first = i;
                qs += res->poses[i].p_qs;
                pqs += res->poses[i].p_pqs;
            }
        const pd_pose *p = &res->poses[first];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", c + 1, clean(p->normal.x),
               clean(p->normal.y), clean(p->normal.z), p->area, p->height, clean(qs), clean(pqs));
        if (gsim)
            printf(",%ld,%ld,%.10g,%.10g,%.10g,%ld,%d", gsim->n, gsim->count[c], gsim->p[c],
                   gsim->ci_lo[c], gsim->ci_hi[c], gsim->unsettled, gsim->partial);
        printf(",");
        for (int i = first, sep = 0; i < res->nposes; i++)
            if (class_of[i] == c) {
                printf(sep ? " %d" : "%d", i + 1);
                sep = 1;
            }
        printf("\n");
    }
}

static void print_facets(const pd_part *part, const pd_static_result *res)
{
    /* Facets are numbered from 1 here, like poses; 0 means "none". */
    int *pose_of = calloc((size_t)res->nfacets, sizeof *pose_of);
    if (pose_of)
        for (int i = 0; i < res->nposes; i++)
            pose_of[res->poses[i].facet] = i + 1;
    printf("facet,nx,ny,nz,area,height,p_raw,stable,knife,next,rest,pose\n");
    for (int f = 0; f < res->nfacets; f++) {
        const pd_facet_result *r = &res->facets[f];
        pd_vec3 n = part->hull->normal[f];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d,%d,%d,%d,%d\n", f + 1, clean(n.x),
               clean(n.y), clean(n.z), r->area, r->height, r->p_raw, r->stable, r->knife,
               r->next + 1, r->rest + 1, pose_of ? pose_of[r->rest] : 0);
    }
    free(pose_of);
}

/* A status as one word of the end column: its fixed name with blanks as
 * underscores ("no convergence": no_convergence). */
static void status_word(pd_status st, char *buf, size_t size)
{
    snprintf(buf, size, "%s", pd_status_str(st));
    for (char *c = buf; *c; c++)
        if (*c == ' ' || *c == '-' || *c == '/')
            *c = '_';
}

/* How a drop ended, as the end column of --trials and --verbose write it:
 * settled, time_limit, collision_limit, or failed:STAGE:STATUS (where a
 * solver failed and how, docs/cli.md). */
static const char *end_name(const pd_trial *t, char *buf, size_t size)
{
    switch (t->end) {
    case PD_END_SETTLED: return "settled";
    case PD_END_TIME_LIMIT: return "time_limit";
    case PD_END_COLLISION_LIMIT: return "collision_limit";
    default: {
        char st[64];
        status_word(t->status, st, sizeof st);
        snprintf(buf, size, "failed:%s:%s", pd_drop_stage_name(t->stage), st);
        return buf;
    }
    }
}

/* A side file (--trials, --transitions). It is made ready before any work,
 * so that a path that cannot be written fails at once (exit 2, nothing on
 * stdout). A regular file, or one that does not exist yet, is written to a
 * temporary file in its directory and renamed onto its path only once every
 * byte is written: a failed or interrupted run never leaves a truncated file
 * that looks like a result, nor destroys the one it would replace. Anything
 * else (a device such as /dev/stdout, a pipe) is opened and written as it
 * is; a write error there (/dev/full) is caught when it is closed. */
typedef struct {
    const char *path;
    char *target; /* where the temporary is renamed to (a symbolic link resolved) */
    char *tmp;    /* NULL when path is written directly */
    FILE *f;
} out_file;

static int out_fail(const char *path, const char *why)
{
    fprintf(stderr, "%s: %s: cannot write: %s\n", prog, path, why);
    return 0;
}

static int out_open(out_file *o, const char *path)
{
    memset(o, 0, sizeof *o);
    o->path = path;
    if (!*path)
        return out_fail("''", "an empty file name");
    struct stat sb;
    int exists = stat(path, &sb) == 0;
    if (exists && S_ISDIR(sb.st_mode))
        return out_fail(path, "is a directory");
    if (exists && !S_ISREG(sb.st_mode)) {
        if (!(o->f = fopen(path, "w")))
            return out_fail(path, strerror(errno));
        return 1;
    }
    if (exists && access(path, W_OK) != 0)
        return out_fail(path, strerror(errno));
    /* A link to a file is followed, as opening it would be. */
    o->target = exists ? realpath(path, NULL) : strdup(path);
    if (!o->target)
        return out_fail(path, strerror(errno));
    const char *slash = strrchr(o->target, '/');
    int dirlen = slash ? (int)(slash - o->target) + 1 : 0;
    size_t size = strlen(o->target) + 32;
    o->tmp = malloc(size);
    if (!o->tmp)
        return out_fail(path, "out of memory");
    snprintf(o->tmp, size, "%.*s.%s.posedrop-XXXXXX", dirlen, o->target,
             slash ? slash + 1 : o->target);
    int fd = mkstemp(o->tmp);
    if (fd < 0) {
        int err = errno;
        free(o->tmp);
        o->tmp = NULL;
        /* Name the directory: the file itself was never the problem. */
        char why[512];
        struct stat db;
        int isdir = snprintf(why, sizeof why, "%.*s", dirlen ? dirlen : 1, dirlen ? o->target : ".") > 0 &&
                    stat(why, &db) == 0 && S_ISDIR(db.st_mode);
        if (isdir)
            snprintf(why, sizeof why, "cannot create a file in %.*s: %s", dirlen ? dirlen : 1,
                     dirlen ? o->target : ".", strerror(err));
        else
            snprintf(why, sizeof why, "no such directory %.*s", dirlen ? dirlen : 1,
                     dirlen ? o->target : ".");
        return out_fail(path, why);
    }
    /* mkstemp makes the file private; give it the mode a new file gets. */
    mode_t mask = umask(0);
    umask(mask);
    if (fchmod(fd, exists ? sb.st_mode & 07777 : 0666 & ~mask) != 0 || !(o->f = fdopen(fd, "w"))) {
        int err = errno;
        close(fd);
        unlink(o->tmp);
        free(o->tmp);
        o->tmp = NULL;
        return out_fail(path, strerror(err));
    }
    return 1;
}

/* Drops what was written (on any failure of the run). */
static void out_abort(out_file *o)
{
    if (o->f)
        fclose(o->f);
    if (o->tmp)
        unlink(o->tmp);
    free(o->tmp);
    free(o->target);
    memset(o, 0, sizeof *o);
}

/* Closes with every write error caught, then puts the file in place. */
static int out_commit(out_file *o)
{
    int ok = fflush(o->f) == 0 && !ferror(o->f);
    int err = errno;
    ok &= fclose(o->f) == 0;
    o->f = NULL;
    if (ok && o->tmp && rename(o->tmp, o->target) != 0) {
        err = errno;
        ok = 0;
    }
    if (!ok)
        fprintf(stderr, "%s: %s: write error: %s\n", prog, o->path, strerror(err ? err : EIO));
    if (ok) {
        free(o->tmp);
        o->tmp = NULL;
    }
    out_abort(o);
    return ok;
}

/* One row per drop. With --group (class_of not NULL) the pose column holds
 * the class number, as in the main output, so the two files join on it; the
 * pose within the class follows in a last column, member. An unsettled drop
 * has pose (and member) 0. */
static void write_trials(FILE *f, const pd_sim_result *sim, const int *class_of,
                         const pd_scene *scene)
{
    fprintf(f, "drop,qw,qx,qy,qz,pose,collisions,time,end%s", class_of ? ",member" : "");
    for (int k = 0; k < PD_NPARAMS; k++)
        if (scene->range[k].kind != PD_DIST_FIXED)
            fprintf(f, ",%s", pd_scene_param_name((pd_scene_param)k));
    fputc('\n', f);
    for (long i = 0; i < sim->n; i++) {
        const pd_trial *t = &sim->trials[i];
        int pose = t->pose < 0 ? 0 : class_of ? class_of[t->pose] + 1 : t->pose + 1;
        long drop = sim->nshards > 0 ? sim->shard + i * sim->nshards : i;
        char end[96];
        fprintf(f, "%ld,%.17g,%.17g,%.17g,%.17g,%d,%d,%.10g,%s", drop + 1, t->q0[0], t->q0[1],
                t->q0[2], t->q0[3], pose, t->collisions, t->time, end_name(t, end, sizeof end));
        if (class_of)
            fprintf(f, ",%d", t->pose + 1);
        for (int k = 0; k < PD_NPARAMS; k++)
            if (scene->range[k].kind != PD_DIST_FIXED)
                fprintf(f, ",%.17g", t->param[k] / (k == PD_PARAM_VIBRATION ? M_PI / 180.0 : 1.0));
        fputc('\n', f);
    }
}

/* The stationary estimator's chain in long format: row 0 is the uniform
 * drops (mu0), rows 1..k the poses (P); every pair is written, zeros
 * included, so the file is the whole matrix. */
static void write_transitions(FILE *f, const pd_sim_result *sim)
{
    int k = sim->nposes;
    fprintf(f, "from_pose,to_pose,count,p\n");
    for (int i = 0; i <= k; i++) {
        const long *row = i == 0 ? sim->first_count : sim->transitions + (size_t)(i - 1) * (size_t)k;
        long total = 0;
        for (int j = 0; j < k; j++)
            total += row[j];
        for (int j = 0; j < k; j++)
            fprintf(f, "%d,%d,%ld,%.10g\n", i, j + 1, row[j],
                    total ? (double)row[j] / (double)total : 0.0);
    }
}

/* --sensitivity: one row per pose (class with --group) and ranged
 * parameter, numbered as in the output. */
static void write_sensitivity(FILE *f, const pd_sensitivity *s)
{
    fprintf(f, "pose,parameter,n_low,p_low,p_low_lo,p_low_hi,n_high,p_high,p_high_lo,p_high_hi,"
               "index,index_lo,index_hi\n");
    for (int i = 0; i < s->nposes * s->nparams; i++) {
        const pd_sensitivity_row *r = &s->rows[i];
        fprintf(f, "%d,%s,%ld,%.10g,%.10g,%.10g,%ld,%.10g,%.10g,%.10g,%.6g,%.6g,%.6g\n",
                r->pose + 1, pd_scene_param_name(r->param), r->n_low, r->p_low, r->p_low_lo,
                r->p_low_hi, r->n_high, r->p_high, r->p_high_lo, r->p_high_hi, r->index,
                r->index_lo, r->index_hi);
    }
}

/* --- the options ------------------------------------------------------------
 * One table drives the parsing (getopt's arrays are built from it), the
 * checking of every value (one number reader and one message form, shared
 * with scene files through base/number.c) and the help. */

enum { OPT_UNITS = 256, OPT_FORMAT, OPT_COM, OPT_TOPPLE, OPT_EPSILON, OPT_PQS_COMPARE,
       OPT_PQS_BAND, OPT_FACETS, OPT_HELP, OPT_VERSION, OPT_VERBOSE, OPT_CI, OPT_SEED,
       OPT_MU, OPT_RESTITUTION, OPT_LAW, OPT_VIBRATION, OPT_INITIAL, OPT_SCENE, OPT_TRIALS,
       OPT_ENGINE, OPT_DT, OPT_GROUP, OPT_TRANSITIONS, OPT_CONTACT_TIME,
       OPT_SVG, OPT_CHART, OPT_SPHERE, OPT_REPORT, OPT_MEASURED, OPT_SHARD, OPT_TUMBLE,
       OPT_SENSITIVITY, OPT_TIME_LIMIT };

typedef enum {
    ARG_HEADING, /* not an option: a heading of the help */
    ARG_FLAG,    /* no value */
    ARG_REAL,    /* a number obeying rule */
    ARG_WHOLE,   /* a whole number obeying rule */
    ARG_CHOICE,  /* one of choices */
    ARG_VEC3,    /* X,Y,Z, each a number obeying rule */
    ARG_INPUT,   /* a path the run reads */
    ARG_OUTPUT,  /* a path the run writes: never the same file as another it reads or writes */
    ARG_TEXT,    /* a value apply() reads itself */
    ARG_SCENE    /* a scene setting: the library checks it by key, as in scene files */
} arg_kind;

typedef struct {
    int id;                      /* getopt's value: the letter, or an OPT_ */
    const char *name;            /* long name; NULL for a letter-only option */
    arg_kind kind;
    const char *arg;             /* the value's name in the help */
    pd_num_rule rule;            /* ARG_REAL, ARG_WHOLE, ARG_VEC3 */
    const char *const *choices;  /* ARG_CHOICE, NULL-terminated */
    const char *key;             /* ARG_SCENE */
    const char *help;            /* lines separated by '\n' */
} cli_option;

#define NO_RULE {0, 0, 0, 0, 0, 0, 0, 0}
#define REAL(what, lo, hi, lo_open, hi_open) {what, 0, lo, hi, lo_open, hi_open, 0, 0}
#define WHOLE(what, lo, hi) {what, 1, 0, 0, 0, 0, lo, hi}
#define HEADING(text) {0, NULL, ARG_HEADING, NULL, NO_RULE, NULL, NULL, text}

static const char *const units_names[] = {"m", "cm", "mm", "in", NULL};
/* The part's format, or the output's. */
static const char *const format_names[] = {"off", "stl", "obj", "csv", "json", NULL};
static const char *const topple_names[] = {"descent", "edge", NULL};
static const char *const compare_names[] = {"raw", "qs", NULL};
static const char *const band_names[] = {"rect", "exact", NULL};
static const char *const engine_names[] = {"impulse", "ode", "bullet", NULL};

static const cli_option options[] = {
    HEADING("part:"),
    {OPT_UNITS, "units", ARG_CHOICE, "U", NO_RULE, units_names, NULL,
     "unit of the file's coordinates: m (default), cm, mm, in"},
    {OPT_FORMAT, "format", ARG_CHOICE, "F", NO_RULE, format_names, NULL,
     "off, stl or obj: the part's (default: detect from content\n"
     "and name); csv (default) or json: the output's"},
    {OPT_COM, "com", ARG_VEC3, "X,Y,Z", REAL("a coordinate", -DBL_MAX, DBL_MAX, 0, 0), NULL, NULL,
     "centre of mass in the file's units (default: computed\n"
     "from the mesh, uniform density); required for meshes\n"
     "that are not closed"},
    HEADING("static estimators:"),
    {OPT_TOPPLE, "topple", ARG_CHOICE, "RULE", NO_RULE, topple_names, NULL,
     "descent (default): exact quasi-static motion, steepest\n"
     "descent of the centre of mass, which may end on a facet\n"
     "sharing only a vertex; edge: the paper's graph between\n"
     "edge-adjacent facets"},
    {OPT_EPSILON, "epsilon", ARG_REAL, "DEG", REAL("an angle in degrees", 0, 90, 0, 0), NULL, NULL,
     "PQS perturbation angle in degrees, 0..90 (default 20)"},
    {OPT_PQS_COMPARE, "pqs-compare", ARG_CHOICE, "C", NO_RULE, compare_names, NULL,
     "raw (default): transfer when the facet's solid-angle\n"
     "probability is lower; qs: compare propagated QS values"},
    {OPT_PQS_BAND, "pqs-band", ARG_CHOICE, "B", NO_RULE, band_names, NULL,
     "rect (default): the paper's |a| x epsilon band clipped\n"
     "to its triangle; exact: exact spherical band area"},
    HEADING("dynamic estimator (simulated drops):"),
    {'n', NULL, ARG_WHOLE, "N", WHOLE("a number of drops", 1, 1000000000), NULL, NULL,
     "drops to simulate, 1..10^9 (default: none)"},
    {OPT_ENGINE, "engine", ARG_CHOICE, "E", NO_RULE, engine_names, NULL,
     "impulse (default): posedrop's own simulator; ode or\n"
     "bullet: the same drops on a stepping engine, to cross-check"},
    {OPT_DT, "dt", ARG_REAL, "S", REAL("a time step in s", 0, 0.01, 1, 0), NULL, NULL,
     "time step of ode (default 0.001) or bullet (1/960),\n"
     "above 0 and at most 0.01"},
    {OPT_TIME_LIMIT, "time-limit", ARG_TEXT, "S", REAL("auto or a time in s", 0, 1e9, 1, 0), NULL, NULL,
     "simulated seconds a drop may take before it ends\n"
     "unsettled (time_limit), above 0 and at most 1e9, or auto\n"
     "(default): 100 (sqrt(L/g) + sqrt(2h/g)) for a part of size\n"
     "L dropped from h, 19.8 s for a 1 cm cube from 0.12 m"},
    {OPT_CI, "ci", ARG_REAL, "DELTA", REAL("a half-width", 0, 0.5, 1, 1), NULL, NULL,
     "drop until every pose's 95% interval is within DELTA\n"
     "(above 0 and below 0.5)"},
    {OPT_SEED, "seed", ARG_WHOLE, "S", WHOLE("a seed", 0, LLONG_MAX), NULL, NULL,
     "random seed, 0..2^63-1 (default 1); same seed, same bytes"},
    {'j', NULL, ARG_WHOLE, "THREADS", WHOLE("a number of threads", 1, 256), NULL, NULL,
     "threads, 1..256 (default: all cores); never changes results"},
    {OPT_SHARD, "shard", ARG_TEXT, "K/N", NO_RULE, NULL, NULL,
     "run only shard K of N: the drops i (from 0) with\n"
     "i mod N = K - 1; prints their counts after a '#' line\n"
     "naming the run, for 'posedrop merge' to sum into the\n"
     "unsharded run's output, byte for byte (docs/batch.md)"},
    {'h', NULL, ARG_SCENE, "H", NO_RULE, NULL, "height",
     "drop height in m: lowest point above the floor, 0..1000\n"
     "(0.12)"},
    {'v', NULL, ARG_SCENE, "V", NO_RULE, NULL, "belt_speed",
     "horizontal belt velocity in m/s, -1000..1000 (0.05)"},
    {OPT_MU, "mu", ARG_SCENE, "MU", NO_RULE, NULL, "mu", "friction coefficient, 0..10 (0.3)"},
    {OPT_RESTITUTION, "restitution", ARG_SCENE, "E", NO_RULE, NULL, "restitution",
     "coefficient of restitution, 0..1 (0.3)"},
    {OPT_LAW, "restitution-law", ARG_SCENE, "L", NO_RULE, NULL, "restitution_law",
     "poisson (default) or energetic"},
    {OPT_VIBRATION, "vibration", ARG_SCENE, "DEG", NO_RULE, NULL, "vibration",
     "initial poses turned by up to DEG about a random axis,\n"
     "0..180 (1.5)"},
    {OPT_CONTACT_TIME, "contact-time", ARG_SCENE, "S", NO_RULE, NULL, "contact_time",
     "how long one contact takes to compress and restore, s,\n"
     "0..1, or auto (default): a plastic part on a rubber belt,\n"
     "5e-4 s for a 1 cm cube, as (volume^2 / size)^(1/5);\n"
     "0: rigid, the paper's model"},
    {OPT_TUMBLE, "tumble", ARG_SCENE, "W", NO_RULE, NULL, "tumble",
     "angular speed at release, rad/s, about an axis drawn\n"
     "uniformly for each drop, 0..10000 (0)"},
    {OPT_INITIAL, "initial", ARG_SCENE, "I", NO_RULE, NULL, "initial",
     "uniform (default): orientations uniform at random;\n"
     "bootstrap: the paper's belt, drops resting on poses drawn\n"
     "from the running estimate, rounds of 100 after 20 uniform;\n"
     "stationary: the belt's long run: of N drops, N/(k+1)\n"
     "start resting on each of the k poses and estimate the\n"
     "pose-to-pose transition matrix P, the rest (at least as\n"
     "many) start uniform and give the first drop's outcome mu0;\n"
     "p = lim (1/T) sum_{t<T} mu0 P^t, solved exactly, with 95%\n"
     "intervals from 1000 multinomial redraws of mu0 and P.\n"
     "Needs N >= 10 (k+1); does not go with --ci. The uniform\n"
     "and resting drops are interleaved from the first drop, so\n"
     "an interrupted run has both in proportion"},
    {OPT_SCENE, "scene", ARG_INPUT, "FILE", NO_RULE, NULL, NULL,
     "'key = value' lines: height, belt_speed, mu, restitution,\n"
     "restitution_law, vibration, initial, gravity,\n"
     "contact_time, tumble, each at most once; options given\n"
     "after it override it.\n"
     "Ranges: -h, -v, --mu, --restitution, --vibration,\n"
     "--contact-time and --tumble (and their keys) take LO:HI\n"
     "as well as a value: each drop draws its own value,\n"
     "uniformly, or log uniformly with LO:HI:log (the default\n"
     "for --contact-time, which also takes multiples of auto,\n"
     "0.3x:3x); the estimates are then over the ranges\n"
     "(docs/uncertainty.md)"},
    {OPT_TRIALS, "trials", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "one CSV row per drop: drop,qw,qx,qy,qz,pose,collisions,time,end\n"
     "(pose 0: unsettled; end: settled, time_limit,\n"
     "collision_limit or failed:STAGE:STATUS, docs/cli.md);\n"
     "with --group, pose is the class\n"
     "number of the output and a last column member the pose\n"
     "within it, numbered as without --group; then one column\n"
     "per ranged scene parameter, named by its key, the value\n"
     "the drop drew (vibration in degrees)"},
    {OPT_SENSITIVITY, "sensitivity", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "with ranges, what each ranged parameter moves, as CSV:\n"
     "pose,parameter,n_low,p_low,p_low_lo,p_low_hi,n_high,\n"
     "p_high,p_high_lo,p_high_hi,index,index_lo,index_hi: the\n"
     "pose's probability in the lower and upper third of the\n"
     "range (95% Wilson) and the first-order index, the share\n"
     "of the pose's variance the parameter explains (95%\n"
     "bootstrap interval; docs/uncertainty.md)"},
    {OPT_TRANSITIONS, "transitions", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "with --initial stationary, the estimated chain as CSV:\n"
     "from_pose,to_pose,count,p, one row per pair of poses\n"
     "(numbered as in the output, classes with --group);\n"
     "count: drops started resting on from_pose that settled\n"
     "in to_pose, p: count over the row's settled drops (P);\n"
     "from_pose 0: the uniform drops (mu0)"},
    HEADING("output:"),
    {OPT_FACETS, "facets", ARG_FLAG, NULL, NO_RULE, NULL, NULL,
     "one row per hull facet instead of per pose, with its\n"
     "stability and quasi-static successor"},
    {OPT_GROUP, "group", ARG_FLAG, NULL, NO_RULE, NULL, NULL,
     "one row per class of poses that a rotation of the part\n"
     "about its centre of mass maps onto each other (a prism's\n"
     "sides; mirror images stay apart): pose = class number,\n"
     "geometry of its first member, p_qs, p_pqs, count and p\n"
     "summed, the class's own interval, and a last column\n"
     "members: the member poses' numbers, space-separated"},
    {OPT_VERBOSE, "verbose", ARG_FLAG, NULL, NO_RULE, NULL, NULL,
     "a summary of the part (and of the drops) on stderr"},
    HEADING("pictures (docs/figures.md):"),
    {OPT_SVG, "svg", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "gallery of the stable poses (classes with --group), SVG"},
    {OPT_CHART, "chart", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "the estimates as grouped bars with 95% intervals, SVG"},
    {OPT_SPHERE, "sphere", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "gravity directions coloured by the pose QS ends in, SVG"},
    {OPT_REPORT, "report", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "one HTML file: part, gallery, chart, sphere, run"},
    {OPT_MEASURED, "measured", ARG_INPUT, "FILE", NO_RULE, NULL, NULL,
     "a measured distribution shown beside the estimates: CSV\n"
     "with columns pose,count or pose,p[,n], numbered as the\n"
     "output (classes with --group)"},
    {OPT_HELP, "help", ARG_FLAG, NULL, NO_RULE, NULL, NULL, "this help"},
    {OPT_VERSION, "version", ARG_FLAG, NULL, NO_RULE, NULL, NULL, "version"},
};
enum { NOPTIONS = sizeof options / sizeof options[0] };

/* "-n" or "--units", for messages and the help. */
static const char *option_name(const cli_option *o, char *buf, size_t size)
{
    if (o->name)
        snprintf(buf, size, "--%s", o->name);
    else
        snprintf(buf, size, "-%c", o->id);
    return buf;
}

static const cli_option *find_option(int id)
{
    for (int i = 0; i < NOPTIONS; i++)
        if (options[i].kind != ARG_HEADING && options[i].id == id)
            return &options[i];
    return NULL;
}

static void usage(FILE *out)
{
    fprintf(out,
        "usage: %s [options] PART\n"
        "       %s merge [options] SHARD...   (sums shards: see 'posedrop merge --help')\n"
        "\n"
        "Predicts the probability of each stable pose of a rigid part dropped on a\n"
        "flat surface and prints one CSV row per stable pose:\n"
        "  pose,nx,ny,nz,area,height,p_qs,p_pqs[,n,count,p,ci_lo,ci_hi,unsettled,partial]\n"
        "pose: 1 = most probable (QS); nx,ny,nz: outward unit normal of the resting\n"
        "facet in the file's frame (gravity's direction in the part's frame); area:\n"
        "facet area in m^2; height: centre of mass above the floor in m; p_qs, p_pqs:\n"
        "quasi-static and perturbed quasi-static estimates. With -n or --ci, drops\n"
        "are simulated too: count of n drops ended in the pose, p = count / n and\n"
        "its 95%% Wilson interval; unsettled: drops that hit a limit (in no count);\n"
        "partial: 1 if interrupted before all drops ran. With --initial stationary,\n"
        "p is the long-run probability of the estimated pose-to-pose chain and\n"
        "ci_lo, ci_hi its 95%% resampled interval; n and count still count drops.\n"
        "\n"
        "PART is an OFF, STL (ASCII or binary) or OBJ file.\n"
        "\n", prog, prog);
    for (int i = 0; i < NOPTIONS; i++) {
        const cli_option *o = &options[i];
        if (o->kind == ARG_HEADING) {
            fprintf(out, "%s\n", o->help);
            continue;
        }
        char name[32], flag[48];
        snprintf(flag, sizeof flag, "%s%s%s", option_name(o, name, sizeof name), o->arg ? " " : "",
                 o->arg ? o->arg : "");
        /* The help column starts at 21; a longer flag pushes its first line. */
        const char *line = o->help;
        for (int first = 1; *line; first = 0) {
            const char *nl = strchr(line, '\n');
            int len = nl ? (int)(nl - line) : (int)strlen(line);
            if (first)
                fprintf(out, "  %-18s %.*s\n", flag, len, line);
            else
                fprintf(out, "%21s%.*s\n", "", len, line);
            line += len + (nl != NULL);
        }
    }
    fprintf(out,
        "\n"
        "Numbers may be written in any C form (0.5, 5e-1); a non-zero number below\n"
        "2.2e-308 in magnitude, nan and inf are refused.\n"
        "\n"
        "exit status: 0 success, 2 bad usage or input, 1 internal failure,\n"
        "130 (SIGINT) or 143 (SIGTERM): interrupted, the drops in flight finished\n"
        "and the rows printed marked partial\n");
}

static int fail_usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n%s: see '%s --help'\n", prog, prog);
    return EXIT_USAGE;
}

/* A refused number: "OPTION: expected WHAT RANGE, got 'TEXT' (WHY)". */
static int fail_number(const cli_option *o, const char *prefix, const char *text, int outcome)
{
    char name[32], msg[256];
    pd_num_message(msg, sizeof msg, &o->rule, text, outcome);
    fprintf(stderr, "%s: %s: %s%s\n%s: see '%s --help'\n", prog, option_name(o, name, sizeof name),
            prefix, msg, prog, prog);
    return EXIT_USAGE;
}

/* "x,y,z": three numbers obeying the option's rule; -1 or an exit code. */
static int parse_vec3(const cli_option *o, const char *text, pd_vec3 *out)
{
    double c[3];
    const char *p = text;
    for (int i = 0; i < 3; i++) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if ((i < 2) != (comma != NULL)) {
            char name[32];
            fprintf(stderr, "%s: %s: expected three numbers X,Y,Z, got '%s'\n%s: see '%s --help'\n",
                    prog, option_name(o, name, sizeof name), text, prog, prog);
            return EXIT_USAGE;
        }
        char buf[128];
        snprintf(buf, sizeof buf, "%.*s", (int)(len < sizeof buf ? len : sizeof buf - 1), p);
        int rc = len < sizeof buf ? pd_num_read(&o->rule, buf, &c[i], NULL) : PD_NUM_BAD;
        if (rc != PD_NUM_OK) {
            char prefix[32];
            snprintf(prefix, sizeof prefix, "%c: ", "XYZ"[i]);
            return fail_number(o, prefix, buf, rc);
        }
        p = comma ? comma + 1 : p + len;
    }
    *out = (pd_vec3){c[0], c[1], c[2]};
    return -1;
}

/* A scene setting given as an option: the library checks it, by the same
 * names and rules as in scene files. */
static int scene_option(cli_args *a, const cli_option *o, const char *value)
{
    pd_diag d;
    pd_diag_init(&d);
    if (pd_scene_set(&a->scene, o->key, value, &d) != PD_OK) {
        char name[32];
        fprintf(stderr, "%s: %s: %s\n%s: see '%s --help'\n", prog, option_name(o, name, sizeof name),
                d.message, prog, prog);
        return EXIT_USAGE;
    }
    return -1;
}

static int choose(const cli_option *o, const char *value, int *out)
{
    int n = 0;
    while (o->choices[n])
        n++;
    for (int i = 0; i < n; i++)
        if (strcmp(value, o->choices[i]) == 0) {
            *out = i;
            return 1;
        }
    char name[32];
    fprintf(stderr, "%s: %s: expected", prog, option_name(o, name, sizeof name));
    for (int i = 0; i < n; i++)
        fprintf(stderr, "%s %s", i ? (i + 1 == n ? " or" : ",") : "", o->choices[i]);
    fprintf(stderr, ", got '%s'\n%s: see '%s --help'\n", value, prog, prog);
    return 0;
}

/* Stores one checked value; -1 to go on, or an exit code (--help, --version,
 * a scene file that cannot be read). */
static int apply(cli_args *a, const cli_option *o, const char *arg, double x, long long n, int k)
{
    switch (o->id) {
    case OPT_UNITS: pd_units_parse(o->choices[k], &a->read.units); break;
    case OPT_FORMAT:
        if (k < 3)
            a->read.format = (pd_mesh_format)(PD_FORMAT_OFF + k);
        else
            a->json = k == 4;
        break;
    case OPT_COM:
        a->part.com_given = 1;
        a->com_text = arg;
        break;
    case OPT_TOPPLE: a->estimate.topple = (pd_topple_rule)k; break;
    case OPT_EPSILON: a->estimate.epsilon = x * (M_PI / 180.0); break;
    case OPT_PQS_COMPARE: a->estimate.compare = (pd_pqs_compare)k; break;
    case OPT_PQS_BAND: a->estimate.band = (pd_pqs_band)k; break;
    case 'n':
        a->sim.ndrops = (long)n;
        a->dynamic = 1;
        break;
    case OPT_CI:
        a->sim.ci_halfwidth = x;
        a->dynamic = 1;
        break;
    case OPT_SEED: a->sim.seed = (uint64_t)n; break;
    case 'j': a->sim.threads = (int)n; break;
    case OPT_ENGINE: a->sim.engine = (pd_engine_kind)k; break;
    case OPT_DT: a->sim.dt = x; break;
    case OPT_TIME_LIMIT: {
        int rc = strcmp(arg, "auto") == 0 ? PD_NUM_OK : pd_num_read(&o->rule, arg, &x, NULL);
        if (rc != PD_NUM_OK)
            return fail_number(o, "", arg, rc);
        a->sim.time_limit = strcmp(arg, "auto") == 0 ? PD_TIME_LIMIT_AUTO : x;
        break;
    }
    case OPT_SCENE: {
        pd_diag d;
        pd_diag_init(&d);
        pd_status st = pd_scene_read(arg, &a->scene, &d);
        if (st != PD_OK) {
            fprintf(stderr, "%s: %s\n", prog, d.message);
            return pd_status_is_input_error(st) ? EXIT_USAGE : EXIT_INTERNAL;
        }
        break;
    }
    case OPT_TRIALS:
        a->trials = arg;
        a->sim.keep_trials = 1;
        break;
    case OPT_TRANSITIONS: a->transitions = arg; break;
    case OPT_SENSITIVITY:
        a->sensitivity = arg;
        a->sim.keep_trials = 1;
        break;
    case OPT_FACETS: a->facets = 1; break;
    case OPT_GROUP: a->group = 1; break;
    case OPT_VERBOSE: a->verbose = 1; break;
    case OPT_SVG: a->pictures[VIZ_GALLERY] = arg; break;
    case OPT_CHART: a->pictures[VIZ_CHART] = arg; break;
    case OPT_SPHERE: a->pictures[VIZ_SPHERE] = arg; break;
    case OPT_REPORT: a->pictures[VIZ_REPORT] = arg; break;
    case OPT_MEASURED: a->measured = arg; break;
    case OPT_SHARD:
        if (!shard_parse(arg, &a->sim))
            return fail_usage("--shard: expected K/N with 1 <= K <= N <= 100000, got '%s'", arg);
        break;
    case OPT_HELP:
        usage(stdout);
        return 0;
    case OPT_VERSION:
        printf("posedrop %s\n", pd_version());
        return 0;
    default: break;
    }
    return -1;
}

/* Checks one option's value by its kind, then stores it; -1 to go on. */
static int take(cli_args *a, const cli_option *o, const char *arg)
{
    double x = 0.0;
    long long n = 0;
    int k = 0, rc;
    switch (o->kind) {
    case ARG_REAL:
    case ARG_WHOLE:
        rc = pd_num_read(&o->rule, arg, &x, &n);
        if (rc != PD_NUM_OK)
            return fail_number(o, "", arg, rc);
        break;
    case ARG_CHOICE:
        if (!choose(o, arg, &k))
            return EXIT_USAGE;
        break;
    case ARG_VEC3:
        if ((rc = parse_vec3(o, arg, &a->part.com)) >= 0)
            return rc;
        break;
    case ARG_SCENE:
        return scene_option(a, o, arg);
    default:
        break;
    }
    return apply(a, o, arg, x, n, k);
}

/* "--re": a prefix of more than one long name, which getopt refuses without
 * saying why. */
static int ambiguous(const char *arg)
{
    if (strncmp(arg, "--", 2) != 0)
        return 0;
    size_t n = strcspn(arg + 2, "=");
    int matches = 0;
    for (int i = 0; i < NOPTIONS; i++)
        matches += options[i].kind != ARG_HEADING && options[i].name &&
                   strncmp(options[i].name, arg + 2, n) == 0;
    return matches > 1;
}

/* Notes a file the run reads or writes. Every input given is read (each
 * --scene in turn); an output given again replaces the earlier one, as only
 * the last is written. option NULL: the PART file. */
static void note_file(cli_args *a, const char *option, const char *path, int output)
{
    int i = 0;
    while (output && i < a->nfiles && strcmp(a->files[i].what, option) != 0)
        i++;
    if (!output || i == a->nfiles)
        i = a->nfiles++;
    a->files[i] = (cli_file){option ? option : "PART", path, output, option != NULL};
}

/* Returns -1 to go on, or an exit code. */
static int parse_args(int argc, char **argv, cli_args *a)
{
    struct option longopts[NOPTIONS + 1];
    char shortopts[2 * NOPTIONS + 2] = ":";
    int nlong = 0;
    for (int i = 0; i < NOPTIONS; i++) {
        const cli_option *o = &options[i];
        if (o->kind == ARG_HEADING)
            continue;
        if (o->name)
            longopts[nlong++] = (struct option){o->name, o->kind == ARG_FLAG ? no_argument
                                                                          : required_argument,
                                                NULL, o->id};
        else
            strcat(shortopts, o->kind == ARG_FLAG ? (char[]){(char)o->id, 0}
                                                  : (char[]){(char)o->id, ':', 0});
    }
    longopts[nlong] = (struct option){0, 0, 0, 0};
    memset(a, 0, sizeof *a);
    a->argc = argc;
    a->argv = argv;
    /* Each file named takes at least one word of argv (the PART one more). */
    if (!(a->files = calloc((size_t)argc + 1, sizeof *a->files))) {
        fprintf(stderr, "%s: out of memory\n", prog);
        return EXIT_INTERNAL;
    }
    pd_mesh_read_options_default(&a->read);
    pd_part_options_default(&a->part);
    pd_static_options_default(&a->estimate);
    pd_scene_default(&a->scene);
    pd_sim_options_default(&a->sim);
    opterr = 0;
    int c, code = -1;
    while (code < 0 && (c = getopt_long(argc, argv, shortopts, longopts, NULL)) != -1) {
        const cli_option *o = find_option(c == ':' || c == '?' ? optopt : c);
        char name[32];
        if (c == ':')
            return fail_usage("option '%s' needs a value", o ? option_name(o, name, sizeof name)
                                                              : argv[optind - 1]);
        if (c == '?' && o && o->kind == ARG_FLAG)
            return fail_usage("option '%s' takes no value", option_name(o, name, sizeof name));
        if (c == '?' && optopt > 0 && optopt < 256) {
            snprintf(name, sizeof name, "-%c", optopt);
            return fail_usage("unknown option '%s'", name);
        }
        if (c == '?' || !o)
            return fail_usage(ambiguous(argv[optind - 1])
                                  ? "option '%s' is the start of more than one option's name"
                                  : "unknown option '%s'",
                              argv[optind - 1]);
        code = take(a, o, optarg);
        if (code < 0 && (o->kind == ARG_INPUT || o->kind == ARG_OUTPUT))
            note_file(a, o->name, optarg, o->kind == ARG_OUTPUT);
    }
    if (code >= 0)
        return code;
    if (optind != argc - 1)
        return fail_usage("%s", optind >= argc ? "expected one PART file" : "expected exactly one PART file");
    note_file(a, NULL, argv[optind], 0);
    if (a->sim.dt > 0 && a->sim.engine == PD_ENGINE_IMPULSE)
        return fail_usage("%s", "--dt sets the time step of the ode and bullet engines only; the "
                          "impulse engine (the default) has no step and would ignore it");
    if (a->trials && !a->dynamic)
        return fail_usage("%s", "--trials needs drops to record (-n or --ci)");
    int stationary = a->scene.initial == PD_INITIAL_STATIONARY;
    if (a->transitions && (!stationary || !a->dynamic))
        return fail_usage("%s", "--transitions needs the drops of --initial stationary and -n");
    if (stationary && a->sim.ci_halfwidth > 0)
        return fail_usage("%s", "--ci does not go with --initial stationary, which splits a fixed "
                          "number of drops over the poses in advance: give -n");
    if (a->sensitivity && (!a->dynamic || !pd_scene_ranged(&a->scene) || a->sim.nshards))
        return fail_usage("%s", "--sensitivity needs drops (-n or --ci) of a scene with a range "
                          "(such as --mu 0.2:0.5), and does not go with --shard");
    /* The report says what each ranged parameter moves. */
    if (a->pictures[VIZ_REPORT] && a->dynamic && pd_scene_ranged(&a->scene))
        a->sim.keep_trials = 1;
    if (a->facets && a->dynamic)
        return fail_usage("%s", "--facets lists hull facets; it does not go with -n or --ci");
    if (a->facets && a->group)
        return fail_usage("%s", "--facets lists hull facets; it does not go with --group");
    const char *const *pic = a->pictures;
    if (a->facets && (pic[VIZ_GALLERY] || pic[VIZ_CHART] || pic[VIZ_SPHERE] || pic[VIZ_REPORT]))
        return fail_usage("%s", "--facets lists hull facets; the pictures show poses");
    if (a->measured && !pic[VIZ_GALLERY] && !pic[VIZ_CHART] && !pic[VIZ_REPORT])
        return fail_usage("%s", "--measured is shown by --svg, --chart or --report: give one");
    if (a->facets && a->json)
        return fail_usage("%s", "--format json lists poses; it does not go with --facets");
    if (a->sim.nshards && (!a->dynamic || a->sim.ci_halfwidth > 0 || a->json || a->transitions ||
                           a->scene.initial == PD_INITIAL_BOOTSTRAP || pic[VIZ_GALLERY] ||
                           pic[VIZ_CHART] || pic[VIZ_SPHERE] || pic[VIZ_REPORT]))
        return fail_usage("%s", "--shard splits the -n drops of a run: it needs -n, and does not go "
                          "with --ci or --initial bootstrap (later drops depend on earlier "
                          "outcomes), nor with --format json, --transitions (give those to "
                          "'posedrop merge') or the pictures");
    a->path = argv[optind];
    /* --com is in the file's units, like the mesh. */
    double s = pd_units_scale(a->read.units);
    a->part.com.x *= s;
    a->part.com.y *= s;
    a->part.com.z *= s;
    return -1;
}

/* Reader messages already start with "FILE:LINE:"; later stages know no file
 * name, so path (when given) is put in front of theirs. */
static int fail_status(pd_status st, const pd_diag *diag, const char *path)
{
    fprintf(stderr, "%s: %s%s%s%s\n", prog, path ? path : "", path ? ": " : "",
            diag->message[0] ? diag->message : pd_status_str(st),
            st == PD_ERR_NOT_CLOSED || st == PD_ERR_ORIENTATION
                ? "; give its centre of mass with --com X,Y,Z to use it anyway" : "");
    return pd_status_is_input_error(st) ? EXIT_USAGE : EXIT_INTERNAL;
}

static void print_summary(const cli_args *a, const pd_part *part, const pd_static_result *res)
{
    const pd_hull *h = part->hull;
    fprintf(stderr, "%s: %d vertices, %d triangles%s; size %.6g m\n", a->path, part->mesh->nverts,
            part->mesh->ntris, part->closed ? "" : " (not closed)", part->size);
    if (part->mass_known)
        fprintf(stderr, "%s: volume %.6g m^3\n", a->path, part->mass.volume);
    const pd_vec3 *c = &part->com, *o = &part->origin; /* in the file's frame */
    fprintf(stderr, "%s: centre of mass (%.9g, %.9g, %.9g) m%s\n", a->path, c->x + o->x,
            c->y + o->y, c->z + o->z, a->part.com_given ? " (given)" : "");
    fprintf(stderr, "%s: hull %d vertices, %d facets; %d stable poses, %d knife edges\n", a->path,
            h->nverts, h->nfacets, res->nposes, res->nknife);
}

/* --initial stationary: whether p is the chain's limit (always said when it
 * is not), and with --verbose how the chain came out: its closed classes, and
 * how far the long run moved from the first drops (mu0 against pi's
 * intervals, which carry mu0's noise too). */
static void print_stationary_summary(const cli_args *a, const pd_sim_result *sim)
{
    if (sim->closed_classes == 0) {
        fprintf(stderr, "%s: %s: the drops run do not define the pose-to-pose chain (a pose it "
                        "reaches has no settled drop started on it, or no uniform drop "
                        "settled): p is count / n\n", prog, a->path);
        return;
    }
    if (!a->verbose)
        return;
    long settled = 0;
    for (int i = 0; i < sim->nposes; i++)
        settled += sim->first_count[i];
    int outside = 0;
    for (int i = 0; i < sim->nposes; i++) {
        double mu0 = (double)sim->first_count[i] / (double)settled;
        outside += mu0 < sim->ci_lo[i] || mu0 > sim->ci_hi[i];
    }
    fprintf(stderr, "%s: stationary: %ld uniform drops, %ld resting on each of %d poses; the "
                    "chain has %d closed class%s reached from the uniform drops%s\n", a->path,
            sim->first_drops, sim->pose_drops, sim->nposes, sim->closed_classes,
            sim->closed_classes == 1 ? "" : "es",
            sim->closed_classes == 1 ? " (pi is its unique stationary distribution)"
                                     : " (pi weighs them by absorption from mu0)");
    fprintf(stderr, "%s: stationary: the first drops (mu0) and the long run (pi) differ by %.3g "
                    "in total variation; mu0 is outside pi's 95%% interval on %d of %d poses%s\n",
            a->path, sim->stationary_shift, outside, sim->nposes,
            outside ? "" : " (no sign that they differ)");
}

/* Why the drops that did not settle ended: how many at each limit (the
 * time limit with its value) and how many failed, with where and how the
 * first failed; --verbose adds a line per such drop when --trials kept
 * them. A merged result from shard files has no breakdown, only the count. */
static void print_unsettled(const cli_args *a, const pd_sim_result *sim)
{
    if (sim->time_limited + sim->collision_limited + sim->failed != sim->unsettled) {
        fprintf(stderr, "%s: %s: %ld of %ld drops did not settle (time or collision limit, or "
                        "a solver failed) and are in no count\n", prog, a->path, sim->unsettled,
                sim->n);
        return;
    }
    fprintf(stderr, "%s: %s: %ld of %ld drops did not settle and are in no count:", prog,
            a->path, sim->unsettled, sim->n);
    const char *sep = "";
    if (sim->time_limited) {
        fprintf(stderr, " %ld at the time limit (%.6g s simulated; --time-limit)",
                sim->time_limited, sim->time_limit);
        sep = ",";
    }
    if (sim->collision_limited) {
        fprintf(stderr, "%s %ld at the collision limit (%d collisions)", sep,
                sim->collision_limited, a->sim.max_collisions);
        sep = ",";
    }
    if (sim->failed) {
        char st[64];
        status_word(sim->failed_status, st, sizeof st);
        fprintf(stderr, "%s %ld failed", sep, sim->failed);
        if (sim->first_failed >= 0) /* not known after posedrop-mpi's sums */
            fprintf(stderr, " (the first, drop %ld: failed:%s:%s)", sim->first_failed + 1,
                    pd_drop_stage_name(sim->failed_stage), st);
    }
    fputc('\n', stderr);
    /* Enough lines to see the pattern; the rest are in the --trials file. */
    enum { VERBOSE_DROPS = 20 };
    long shown = 0;
    for (long i = 0; a->verbose && sim->trials && i < sim->n; i++) {
        const pd_trial *t = &sim->trials[i];
        if (t->end == PD_END_SETTLED)
            continue;
        if (shown++ == VERBOSE_DROPS) {
            fprintf(stderr, "%s: and %ld more drops that did not settle, in %s\n", a->path,
                    sim->unsettled - VERBOSE_DROPS, a->trials);
            break;
        }
        char end[96];
        long drop = sim->nshards > 0 ? sim->shard + i * sim->nshards : i;
        fprintf(stderr, "%s: drop %ld: %s after %.6g s simulated, %d collisions\n", a->path,
                drop + 1, end_name(t, end, sizeof end), t->time, t->collisions);
    }
}

/* What every dynamic run reports, whether or not --verbose: drops that could
 * not be classified and collisions the law had to correct are never silent. */
static void print_sim_summary(const cli_args *a, const pd_sim_result *sim)
{
    if (sim->unsettled)
        print_unsettled(a, sim);
    if (sim->energy_gain)
        fprintf(stderr, "%s: %s: %ld collisions would have added energy (Poisson's law with "
                        "friction, resolved by the energetic law; or a compliant impact's step, "
                        "scaled back)\n", prog, a->path,
                sim->energy_gain);
    if (sim->fallbacks)
        fprintf(stderr, "%s: %s: %ld of %ld collisions could not be integrated to the end and "
                        "were resolved by stopping the contact within the friction cone\n", prog,
                a->path, sim->fallbacks, sim->collisions);
    if (sim->bootstrap_rounds)
        fprintf(stderr, "%s: %s: bootstrap: %d rounds; the last round ended %.3g (total "
                        "variation) from the distribution it started from%s\n", prog, a->path,
                sim->bootstrap_rounds, sim->stationarity,
                sim->stationarity > 0.1 ? " -- not yet stationary, drop more" : "");
    if (sim->transitions && sim->nshards == 0) {
        print_stationary_summary(a, sim);
        fragile_warn(a->path, sim);
    }
    if (a->verbose && sim->n)
        fprintf(stderr, "%s: %ld drops, %.2f collisions per drop\n", a->path, sim->n,
                (double)sim->collisions / (double)sim->n);
    if (sim->partial)
        fprintf(stderr, "%s: interrupted after %ld drops: results are partial\n", prog, sim->n);
}

/* Seconds on a monotonic clock, for the report's timings. */
static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int cli_run(cli_args *a)
{
    /* Before anything is read for the run or written. */
    if (cli_any(!cli_files_apart(a->files, a->nfiles)))
        return EXIT_USAGE;
    int code;
    pd_diag diag;
    pd_diag_init(&diag);
    diag.warn = print_warning;
    /* The command offers every engine: it links libposedrop-bullet. */
    pd_status st = pd_bullet_register();
    if (st != PD_OK) {
        fprintf(stderr, "%s: the Bullet engine: %s\n", prog, pd_status_str(st));
        return EXIT_INTERNAL;
    }

    /* Output paths first: a run never does its work only to fail writing.
     * Every MPI rank checks them, so that all stop together; only rank 0
     * puts its files in place (the others' are dropped at the end). */
    out_file trials_out = {0}, transitions_out = {0}, sens_out = {0}, pic_out[VIZ_KINDS] = {{0}};
    int opened = (!a->trials || out_open(&trials_out, a->trials)) &&
                 (!a->transitions || out_open(&transitions_out, a->transitions)) &&
                 (!a->sensitivity || out_open(&sens_out, a->sensitivity));
    for (int k = 0; k < VIZ_KINDS && opened; k++)
        opened = !a->pictures[k] || out_open(&pic_out[k], a->pictures[k]);
    /* A measured distribution is read before the work too. */
    viz_measured *measured = NULL;
    double t0 = now(), t_static = 0.0, t_sim = 0.0;
    if (opened && a->measured && (st = viz_measured_read(a->measured, &measured, &diag)) != PD_OK) {
        fail_status(st, &diag, NULL);
        opened = 0;
    }
    if (!opened) {
        out_abort(&trials_out);
        out_abort(&transitions_out);
        out_abort(&sens_out);
        for (int k = 0; k < VIZ_KINDS; k++)
            out_abort(&pic_out[k]);
        return EXIT_USAGE;
    }

    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    pd_sim_result *sim = NULL, *gsim = NULL;
    pd_sensitivity *sens = NULL;
    int *class_of = NULL, nclasses = 0;
    st = pd_mesh_read(a->path, &a->read, &mesh, &diag);
    if (st != PD_OK) {
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    st = pd_part_build(mesh, &a->part, &part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(part, &a->estimate, &res, &diag);
    t_static = now() - t0;
    /* A signal before the drops (or, without drops, before the output)
     * ends the run here, nothing printed. */
    if (st == PD_OK && cli_any(signals_caught())) {
        code = cli_interrupt_code();
        goto done;
    }
    if (st == PD_OK && a->dynamic) {
        st = cli_simulate(part, res, a, &sim, &diag);
        t_sim = now() - t0 - t_static;
    }
    if (st == PD_OK && !cli_writer()) {
        code = 0;
        goto done;
    }
    /* A shard prints its poses' own counts; its merge groups them. */
    if (st == PD_OK && a->group && !a->sim.nshards) {
        class_of = malloc(sizeof *class_of * (size_t)(res->nposes + 1));
        st = class_of ? pd_pose_classes(part, res, class_of, &nclasses, &diag) : PD_ERR_NOMEM;
        if (st == PD_OK && sim)
            st = pd_sim_result_grouped(sim, class_of, nclasses, &gsim, &diag);
    }
    /* The report shows it when the drops' records were kept (not across
     * MPI ranks); --sensitivity needs them. */
    if (st == PD_OK && sim && pd_scene_ranged(&a->scene) &&
        (a->sensitivity || (a->pictures[VIZ_REPORT] && sim->trials)))
        st = pd_sim_sensitivity(sim, &a->scene, pd_contact_time_auto_size(part), class_of,
                                nclasses, &sens, &diag);
    static const char *const engine_labels[] = {"impulse", "ODE", "Bullet"};
    viz_input in = {a->path, part, res, gsim ? gsim : sim, class_of, nclasses,
                    engine_labels[a->sim.engine], sim ? &a->scene : NULL, measured, sens};
    if (st == PD_OK && measured && (st = viz_check(&in, &diag)) != PD_OK) {
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    if (st != PD_OK) {
        code = fail_status(st, &diag, a->path);
        goto done;
    }
    /* The side files before stdout: if one cannot be written in full (a
     * full disk, /dev/full), the run fails with nothing on stdout. */
    if (trials_out.f)
        write_trials(trials_out.f, sim, class_of, &a->scene);
    if (transitions_out.f)
        write_transitions(transitions_out.f, gsim ? gsim : sim);
    if (sens_out.f)
        write_sensitivity(sens_out.f, sens);
    if ((trials_out.f && !out_commit(&trials_out)) ||
        (transitions_out.f && !out_commit(&transitions_out)) ||
        (sens_out.f && !out_commit(&sens_out))) {
        code = EXIT_INTERNAL;
        goto done;
    }
    viz_run run = {a->path, a->read.units, &a->estimate, &a->sim, t_static, t_sim, now() - t0,
                   a->argc, a->argv};
    for (int k = 0; k < VIZ_KINDS; k++) {
        if (!pic_out[k].f)
            continue;
        if ((st = viz_write_file((viz_kind)k, pic_out[k].f, &in, &run, &diag)) != PD_OK) {
            code = fail_status(st, &diag, NULL);
            goto done;
        }
        if (!out_commit(&pic_out[k])) {
            code = EXIT_INTERNAL;
            goto done;
        }
    }
    if (a->verbose)
        print_summary(a, part, res);
    if (sim)
        print_sim_summary(a, sim);
    if (a->sim.nshards && !shard_write_identity(stdout, a, sim)) {
        code = EXIT_INTERNAL;
        goto done;
    }
    if (a->json)
        json_print(stdout, a, part, res, gsim ? gsim : sim, class_of, nclasses, now() - t0);
    else if (a->facets)
        print_facets(part, res);
    else if (class_of)
        print_classes(res, gsim, class_of, nclasses);
    else
        print_poses(res, sim);
    code = fflush(stdout) == 0 && !ferror(stdout) ? 0 : EXIT_INTERNAL;
    if (code)
        fprintf(stderr, "%s: error writing the output: %s\n", prog, strerror(errno));
    if (code == 0 && sim && sim->partial)
        code = cli_interrupt_code();
    else if (code == 0 && sim && sim->n > 0 && sim->failed == sim->n) {
        /* Not one drop ran to an end the model defines: the rows hold the
         * static estimates only, and a script must not take them for a run. */
        fprintf(stderr, "%s: %s: every drop failed: no dynamic estimate\n", prog, a->path);
        code = EXIT_INTERNAL;
    }
done:
    out_abort(&trials_out);
    out_abort(&transitions_out);
    out_abort(&sens_out);
    pd_sensitivity_free(sens);
    for (int k = 0; k < VIZ_KINDS; k++)
        out_abort(&pic_out[k]);
    viz_measured_free(measured);
    free(class_of);
    pd_sim_result_free(gsim);
    pd_sim_result_free(sim);
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return code;
}

int main(int argc, char **argv)
{
    /* Before anything else: a signal in the first moments is caught, not
     * left to the default action that ends the process unannounced. */
    signals_install();
    cli_start(&argc, &argv);
    if (argc > 1 && strcmp(argv[1], "merge") == 0)
        return cli_end(cli_merge(argc - 1, argv + 1));
    cli_args a;
    int code = parse_args(argc, argv, &a);
    if (code < 0)
        code = cli_run(&a);
    free(a.files);
    return cli_end(code);
}
