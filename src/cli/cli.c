/* cli.c: the posedrop command, a thin client of libposedrop.
 *
 * It parses the arguments into cli_args (cli/args.h) and hands them to
 * cli_run (command.c), which calls the library and prints: the results as
 * CSV on stdout, diagnostics on stderr; 'posedrop merge' goes to merge.c,
 * 'posedrop fit' to fit_cmd.c. Exit codes: 0 success, 2 bad usage or
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
#include "base/number.h" /* one reading of numbers, shared with scene files */
#include "cli/cli.h"
#include "cli/command.h"
#include "cli/merge.h"

/* --- the options ------------------------------------------------------------
 * One table drives the parsing (getopt's arrays are built from it), the
 * checking of every value (one number reader and one message form, shared
 * with scene files through base/number.c) and the help. */

enum { OPT_UNITS = 256, OPT_FORMAT, OPT_COM, OPT_TOPPLE, OPT_EPSILON, OPT_PQS_COMPARE,
       OPT_PQS_BAND, OPT_FACETS, OPT_HELP, OPT_VERSION, OPT_VERBOSE, OPT_CI, OPT_SEED,
       OPT_MU, OPT_RESTITUTION, OPT_LAW, OPT_VIBRATION, OPT_INITIAL, OPT_SCENE, OPT_TRIALS,
       OPT_ENGINE, OPT_DT, OPT_GROUP, OPT_TRANSITIONS, OPT_CONTACT_TIME,
       OPT_SVG, OPT_CHART, OPT_SPHERE, OPT_REPORT, OPT_MEASURED, OPT_SHARD, OPT_TUMBLE,
       OPT_SENSITIVITY, OPT_TIME_LIMIT, OPT_CROSSCHECK, OPT_EFFECT, OPT_TRACE, OPT_TRACE_DROP,
       OPT_PROGRESS };

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
    {OPT_DT, "dt", ARG_TEXT, "S", REAL("auto or a time step in s", 0, 0.01, 1, 0), NULL, NULL,
     "time step of ode and bullet, above 0 and at most 0.01,\n"
     "or auto (default): 20 steps per contact time (the\n"
     "shortest the scene draws), each corner travelling at\n"
     "most a tenth of the part's thickness per step"},
    {OPT_CROSSCHECK, "crosscheck", ARG_FLAG, NULL, NO_RULE, NULL, NULL,
     "the same drops (the same releases) on all three engines;\n"
     "p and its interval stay --engine's, and each row adds\n"
     "p_impulse, p_ode, p_bullet, their lowest and highest,\n"
     "p_engine_min and p_engine_max, and engines_disagree: 1\n"
     "when two engines' 95% intervals are apart (the model, not\n"
     "the sampling, limits that estimate); said on stderr too.\n"
     "Costs the three runs together (docs/engines.md)"},
    {OPT_TIME_LIMIT, "time-limit", ARG_TEXT, "S", REAL("auto or a time in s", 0, 1e9, 1, 0), NULL, NULL,
     "simulated seconds a drop may take before it ends\n"
     "unsettled (time_limit), above 0 and at most 1e9, or auto\n"
     "(default): 100 (sqrt(L/g) + sqrt(2h/g)) for a part of size\n"
     "L dropped from h, 19.8 s for a 1 cm cube from 0.12 m; the\n"
     "impulse engine leaves out the time a drop spends spinning\n"
     "on one vertex (a top), up to the longest spin drilling\n"
     "friction allows it"},
    {OPT_CI, "ci", ARG_REAL, "DELTA", REAL("a half-width", 0, 0.5, 1, 1), NULL, NULL,
     "drop until every pose's 95% interval is within DELTA\n"
     "(above 0 and below 0.5)"},
    {OPT_EFFECT, "effect", ARG_REAL, "DELTA", REAL("a half-width", 0, 0.5, 1, 1), NULL, NULL,
     "with a range, drop (from -n, in rounds) until every\n"
     "effect's 95% interval is within DELTA (0.03: 3 points\n"
     "each side; --sensitivity, docs/uncertainty.md)"},
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
     "5e-4 s for a 1 cm cube, as (volume^2 / size)^(1/5), or a\n"
     "multiple of it (3x); 0: rigid, the paper's model"},
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
     "the drop drew (vibration in degrees); last partial, 1 in\n"
     "every row of an interrupted run"},
    {OPT_TRACE, "trace", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "one drop's motion as CSV, the same columns on every\n"
     "engine: t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,energy,\n"
     "depth,contacts,event (docs/engines.md, \"Tracing a drop\");\n"
     "a stepping engine's every step, the impulse engine's\n"
     "every event"},
    {OPT_TRACE_DROP, "trace-drop", ARG_WHOLE, "I", WHOLE("a drop number", 0, LONG_MAX), NULL, NULL,
     "the drop --trace records, numbered from 0 (default 0):\n"
     "the same I starts from the same state on every engine"},
    {OPT_SENSITIVITY, "sensitivity", ARG_OUTPUT, "FILE", NO_RULE, NULL, NULL,
     "with ranges, what each ranged parameter moves, as CSV:\n"
     "pose,parameter,effect,effect_lo,effect_hi,n_low,p_low,...,\n"
     "index,index_lo,index_hi,interacts,...: the effect, how far\n"
     "the pose's probability moves from the range's lower third\n"
     "to its upper (95% bootstrap interval), the thirds' p (95%\n"
     "Wilson), the first-order index, and the parameter across\n"
     "whose thirds the effect changes, if any; stderr says what\n"
     "effect the drops resolve; last partial, 1 in every row\n"
     "of an interrupted run (docs/uncertainty.md)"},
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
    {OPT_PROGRESS, "progress", ARG_FLAG, NULL, NO_RULE, NULL, NULL,
     "a progress line on stderr even when it is not a terminal\n"
     "(on a terminal it is drawn anyway): the drops done, and\n"
     "the stage of a part whose static estimate passes 2 s"},
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
        "       %s fit [options] --fit SPEC --part PART --measured CSV ...\n"
        "                             (calibrates the scene: see 'posedrop fit --help')\n"
        "       %s design [options] --vary SPEC --target CSV --out OFF PART\n"
        "                             (changes the part to a target: see 'posedrop design --help')\n"
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
        "\n", prog, prog, prog, prog);
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
    if (!a->scene_option[0])
        option_name(o, a->scene_option, sizeof a->scene_option);
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
    case OPT_EFFECT:
        a->sim.effect_halfwidth = x;
        a->sim.keep_trials = 1;
        a->dynamic = 1;
        break;
    case OPT_SEED: a->sim.seed = (uint64_t)n; break;
    case 'j': a->sim.threads = (int)n; break;
    case OPT_ENGINE: a->sim.engine = (pd_engine_kind)k; break;
    case OPT_DT: {
        int rc = strcmp(arg, "auto") == 0 ? PD_NUM_OK : pd_num_read(&o->rule, arg, &x, NULL);
        if (rc != PD_NUM_OK)
            return fail_number(o, "", arg, rc);
        a->sim.dt = strcmp(arg, "auto") == 0 ? 0.0 : x;
        break;
    }
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
        if (!a->scene_option[0])
            snprintf(a->scene_option, sizeof a->scene_option, "--scene");
        break;
    }
    case OPT_TRIALS:
        a->trials = arg;
        a->sim.keep_trials = 1;
        break;
    case OPT_TRANSITIONS: a->transitions = arg; break;
    case OPT_TRACE: a->trace = arg; break;
    case OPT_TRACE_DROP: a->sim.trace_drop = (long)n; break;
    case OPT_SENSITIVITY:
        a->sensitivity = arg;
        a->sim.keep_trials = 1;
        break;
    case OPT_FACETS: a->facets = 1; break;
    case OPT_GROUP: a->group = 1; break;
    case OPT_CROSSCHECK: a->crosscheck = 1; break;
    case OPT_VERBOSE: a->verbose = 1; break;
    case OPT_PROGRESS: progress_force(); break;
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
    if (a->sim.dt > 0 && a->sim.engine == PD_ENGINE_IMPULSE && !a->crosscheck)
        return fail_usage("%s", "--dt sets the time step of the ode and bullet engines only; the "
                          "impulse engine (the default) has no step and would ignore it");
    if (a->crosscheck && (!a->dynamic || a->sim.nshards))
        return fail_usage("%s", "--crosscheck runs the drops on every engine: it needs -n or --ci, "
                          "and does not go with --shard");
    if (a->trials && !a->dynamic)
        return fail_usage("%s", "--trials needs drops to record (-n or --ci)");
    if (a->trace && !a->dynamic)
        return fail_usage("%s", "--trace needs drops to record (-n or --ci)");
    int stationary = a->scene.initial == PD_INITIAL_STATIONARY;
    if (a->transitions && (!stationary || !a->dynamic))
        return fail_usage("%s", "--transitions needs the drops of --initial stationary and -n");
    if (stationary && a->sim.ci_halfwidth > 0)
        return fail_usage("%s", "--ci does not go with --initial stationary, which splits a fixed "
                          "number of drops over the poses in advance: give -n");
    if (a->sim.effect_halfwidth > 0 && (!pd_scene_ranged(&a->scene) || a->sim.nshards ||
                                        a->scene.initial != PD_INITIAL_UNIFORM))
        return fail_usage("%s", "--effect needs a scene with a range (such as --mu 0.2:0.5) and "
                          "the uniform start, and does not go with --shard (the drops' number "
                          "comes from their effects)");
    if (a->sensitivity && (!a->dynamic || !pd_scene_ranged(&a->scene) || a->sim.nshards))
        return fail_usage("%s", "--sensitivity needs drops (-n or --ci) of a scene with a range "
                          "(such as --mu 0.2:0.5), and does not go with --shard");
    /* The report says what each ranged parameter moves. */
    if (a->pictures[VIZ_REPORT] && a->dynamic && pd_scene_ranged(&a->scene))
        a->sim.keep_trials = 1;
    if (a->facets && a->dynamic)
        return fail_usage("%s", "--facets lists hull facets; it does not go with -n or --ci");
    /* QS and PQS depend on the part alone: a scene given without drops
     * would change nothing, silently. */
    if (a->scene_option[0] && !a->dynamic)
        fprintf(stderr, "%s: warning: %s (like every scene option) applies to drops, and none "
                        "are run: give -n N to drop the part\n", prog, a->scene_option);
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
    /* The library's own checks of what the options set, so that the command
     * accepts nothing the library would refuse later. */
    pd_diag d;
    pd_diag_init(&d);
    if (pd_static_options_check(&a->estimate, &d) != PD_OK ||
        pd_sim_options_check(&a->sim, &d) != PD_OK)
        return fail_usage("%s", d.message);
    a->path = argv[optind];
    /* --com is in the file's units, like the mesh. */
    double s = pd_units_scale(a->read.units);
    a->part.com.x *= s;
    a->part.com.y *= s;
    a->part.com.z *= s;
    return -1;
}

int main(int argc, char **argv)
{
    /* Before anything else: a signal in the first moments is caught, not
     * left to the default action that ends the process unannounced. */
    signals_install();
    cli_start(&argc, &argv);
    if (argc > 1 && strcmp(argv[1], "merge") == 0)
        return cli_end(cli_merge(argc - 1, argv + 1));
    if (argc > 1 && strcmp(argv[1], "fit") == 0)
        return cli_end(cli_fit(argc - 1, argv + 1));
    if (argc > 1 && strcmp(argv[1], "design") == 0)
        return cli_end(cli_design(argc - 1, argv + 1));
    cli_args a;
    int code = parse_args(argc, argv, &a);
    if (code < 0)
        code = cli_run(&a);
    free(a.files);
    return cli_end(code);
}
