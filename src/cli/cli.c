/* cli.c: the posedrop command, a thin client of libposedrop.
 *
 * It only parses arguments, calls the library and prints: the results as CSV
 * on stdout, diagnostics on stderr. Exit codes: 0 success, 2 bad usage or
 * input (nothing is printed on stdout), 1 internal failure, 130 interrupted
 * (what was done is printed, marked partial). */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "posedrop/posedrop.h"

enum { EXIT_USAGE = 2, EXIT_INTERNAL = 1, EXIT_INTERRUPTED = 130 };

static const char *prog = "posedrop";

static void usage(FILE *out)
{
    fprintf(out,
        "usage: %s [options] PART\n"
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
        "\n"
        "part:\n"
        "  --units U          unit of the file's coordinates: m (default), cm, mm, in\n"
        "  --format F         off, stl or obj (default: detect from content and name)\n"
        "  --com X,Y,Z        centre of mass in the file's units (default: computed\n"
        "                     from the mesh, uniform density); required for meshes\n"
        "                     that are not closed\n"
        "static estimators:\n"
        "  --topple RULE      descent (default): exact quasi-static motion, steepest\n"
        "                     descent of the centre of mass, which may end on a facet\n"
        "                     sharing only a vertex; edge: the paper's graph between\n"
        "                     edge-adjacent facets\n"
        "  --epsilon DEG      PQS perturbation angle in degrees, 0..90 (default 20)\n"
        "  --pqs-compare C    raw (default): transfer when the facet's solid-angle\n"
        "                     probability is lower; qs: compare propagated QS values\n"
        "  --pqs-band B       rect (default): the paper's |a| x epsilon band clipped\n"
        "                     to its triangle; exact: exact spherical band area\n"
        "dynamic estimator (simulated drops):\n", prog);
    /* Two strings: C11 compilers need only take 4095 characters in one. */
    fprintf(out,
        "  -n N               drops to simulate (default: none)\n"
        "  --engine E         impulse (default): posedrop's own simulator; ode or\n"
        "                     bullet: the same drops on a stepping engine, to cross-check\n"
        "  --dt S             time step of ode (default 0.001) or bullet (1/960)\n"
        "  --ci DELTA         drop until every pose's 95%% interval is within DELTA\n"
        "  --seed S           random seed (default 1); same seed, same bytes\n"
        "  -j THREADS         threads (default: all cores); never changes results\n"
        "  -h H               drop height in m: lowest point above the floor (0.12)\n"
        "  -v V               horizontal belt velocity in m/s (0.05)\n"
        "  --mu MU            friction coefficient (0.3)\n"
        "  --restitution E    coefficient of restitution (0.3)\n"
        "  --restitution-law L  poisson (default) or energetic\n"
        "  --vibration DEG    initial poses turned by up to DEG about a random axis (1.5)\n"
        "  --contact-time S   how long one contact takes to compress and restore, s\n"
        "                     (a material property; 5e-4, a plastic part on a rubber\n"
        "                     belt; 0: rigid, the paper's model)\n"
        "  --initial I        uniform (default): orientations uniform at random;\n"
        "                     bootstrap: the paper's belt, drops resting on poses drawn\n"
        "                     from the running estimate, rounds of 100 after 20 uniform;\n"
        "                     stationary: the belt's long run: of N drops, N/(k+1)\n"
        "                     start resting on each of the k poses and estimate the\n"
        "                     pose-to-pose transition matrix P, the rest (at least as\n"
        "                     many) start uniform and give the first drop's outcome mu0;\n"
        "                     p = lim (1/T) sum_{t<T} mu0 P^t, solved exactly, with 95%%\n"
        "                     intervals from 1000 multinomial redraws of mu0 and P.\n"
        "                     Needs N >= 10 (k+1); does not go with --ci\n"
        "  --scene FILE       'key = value' lines: height, belt_speed, mu, restitution,\n"
        "                     restitution_law, vibration, initial, gravity,\n"
        "                     contact_time; options given after it override it\n"
        "  --trials FILE      one CSV row per drop: drop,qw,qx,qy,qz,pose,collisions,time,end\n"
        "                     (pose 0: unsettled); with --group, pose is the class\n"
        "                     number of the output and a last column member the pose\n"
        "                     within it, numbered as without --group\n"
        "  --transitions FILE with --initial stationary, the estimated chain as CSV:\n"
        "                     from_pose,to_pose,count,p, one row per pair of poses\n"
        "                     (numbered as in the output, classes with --group);\n"
        "                     count: drops started resting on from_pose that settled\n"
        "                     in to_pose, p: count over the row's settled drops (P);\n"
        "                     from_pose 0: the uniform drops (mu0)\n"
        "output:\n"
        "  --facets           one row per hull facet instead of per pose, with its\n"
        "                     stability and quasi-static successor\n"
        "  --group            one row per class of poses that a rotation of the part\n"
        "                     about its centre of mass maps onto each other (a prism's\n"
        "                     sides; mirror images stay apart): pose = class number,\n"
        "                     geometry of its first member, p_qs, p_pqs, count and p\n"
        "                     summed, the class's own interval, and a last column\n"
        "                     members: the member poses' numbers, space-separated\n"
        "  --verbose          a summary of the part (and of the drops) on stderr\n"
        "  --help             this help\n"
        "  --version          version\n"
        "\n"
        "exit status: 0 success, 2 bad usage or input, 1 internal failure,\n"
        "130 interrupted (the rows printed are marked partial)\n");
}

static int fail_usage(const char *fmt, const char *arg)
{
    fprintf(stderr, "%s: ", prog);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, "\n%s: see '%s --help'\n", prog, prog);
    return EXIT_USAGE;
}

/* Strict: the whole text must be one finite number. */
static int parse_double(const char *text, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !isfinite(v))
        return 0;
    *out = v;
    return 1;
}

/* Strict: the whole text one integer in [lo, hi]. */
static int parse_long(const char *text, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long long v = strtoll(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || v < lo || v > hi)
        return 0;
    *out = (long)v;
    return 1;
}

/* "x,y,z" with three finite numbers. */
static int parse_vec3(const char *text, pd_vec3 *out)
{
    double c[3];
    const char *p = text;
    for (int i = 0; i < 3; i++) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        if ((i < 2) != (comma != NULL) || len == 0 || len >= 64)
            return 0;
        char buf[64];
        memcpy(buf, p, len);
        buf[len] = '\0';
        if (!parse_double(buf, &c[i]))
            return 0;
        p = comma ? comma + 1 : p + len;
    }
    out->x = c[0];
    out->y = c[1];
    out->z = c[2];
    return 1;
}

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

static void print_poses(const pd_static_result *res, const pd_sim_result *sim)
{
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs%s\n",
           sim ? ",n,count,p,ci_lo,ci_hi,unsettled,partial" : "");
    for (int i = 0; i < res->nposes; i++) {
        const pd_pose *p = &res->poses[i];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", i + 1, clean(p->normal.x),
               clean(p->normal.y), clean(p->normal.z), p->area, p->height, clean(p->p_qs),
               clean(p->p_pqs));
        if (sim)
            printf(",%ld,%ld,%.10g,%.10g,%.10g,%ld,%d", sim->n, sim->count[i], sim->p[i],
                   sim->ci_lo[i], sim->ci_hi[i], sim->unsettled, sim->partial);
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

static const char *end_name(pd_drop_end e)
{
    switch (e) {
    case PD_END_SETTLED: return "settled";
    case PD_END_TIME_LIMIT: return "time_limit";
    case PD_END_COLLISION_LIMIT: return "collision_limit";
    default: return "failed";
    }
}

/* The side files (--trials, --transitions): opened with a message on
 * failure, closed with every write error caught. */
static FILE *open_output(const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        fprintf(stderr, "%s: %s: cannot write: %s\n", prog, path, strerror(errno));
    return f;
}

static int close_output(FILE *f, const char *path)
{
    int ok = fflush(f) == 0 && !ferror(f);
    ok &= fclose(f) == 0;
    if (!ok)
        fprintf(stderr, "%s: %s: write error\n", prog, path);
    return ok;
}

/* One row per drop. With --group (class_of not NULL) the pose column holds
 * the class number, as in the main output, so the two files join on it; the
 * pose within the class follows in a last column, member. An unsettled drop
 * has pose (and member) 0. */
static int write_trials(const char *path, const pd_sim_result *sim, const int *class_of)
{
    FILE *f = open_output(path);
    if (!f)
        return 0;
    fprintf(f, "drop,qw,qx,qy,qz,pose,collisions,time,end%s\n", class_of ? ",member" : "");
    for (long i = 0; i < sim->n; i++) {
        const pd_trial *t = &sim->trials[i];
        int pose = t->pose < 0 ? 0 : class_of ? class_of[t->pose] + 1 : t->pose + 1;
        fprintf(f, "%ld,%.17g,%.17g,%.17g,%.17g,%d,%d,%.10g,%s", i + 1, t->q0[0], t->q0[1],
                t->q0[2], t->q0[3], pose, t->collisions, t->time, end_name(t->end));
        if (class_of)
            fprintf(f, ",%d", t->pose + 1);
        fputc('\n', f);
    }
    return close_output(f, path);
}

/* The stationary estimator's chain in long format: row 0 is the uniform
 * drops (mu0), rows 1..k the poses (P); every pair is written, zeros
 * included, so the file is the whole matrix. */
static int write_transitions(const char *path, const pd_sim_result *sim)
{
    FILE *f = open_output(path);
    if (!f)
        return 0;
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
    return close_output(f, path);
}

typedef struct {
    const char *path, *trials, *transitions, *com_text;
    pd_mesh_read_options read;
    pd_part_options part;
    pd_static_options estimate;
    pd_scene scene;
    pd_sim_options sim;
    int dynamic, facets, group, verbose;
} cli_args;

enum { OPT_UNITS = 256, OPT_FORMAT, OPT_COM, OPT_TOPPLE, OPT_EPSILON, OPT_PQS_COMPARE,
       OPT_PQS_BAND, OPT_FACETS, OPT_HELP, OPT_VERSION, OPT_VERBOSE, OPT_CI, OPT_SEED,
       OPT_MU, OPT_RESTITUTION, OPT_LAW, OPT_VIBRATION, OPT_INITIAL, OPT_SCENE, OPT_TRIALS,
       OPT_ENGINE, OPT_DT, OPT_GROUP, OPT_TRANSITIONS, OPT_CONTACT_TIME };

/* A scene setting given as an option: the library checks it, by the same
 * names and rules as in scene files. */
static int scene_option(cli_args *a, const char *option, const char *key, const char *value)
{
    pd_diag d;
    pd_diag_init(&d);
    if (pd_scene_set(&a->scene, key, value, &d) != PD_OK) {
        fprintf(stderr, "%s: %s: %s\n%s: see '%s --help'\n", prog, option, d.message, prog, prog);
        return EXIT_USAGE;
    }
    return -1;
}

static int choose(const char *option, const char *value, const char *const *names, int n,
                  int *out)
{
    for (int i = 0; i < n; i++)
        if (strcmp(value, names[i]) == 0) {
            *out = i;
            return 1;
        }
    fprintf(stderr, "%s: %s: expected", prog, option);
    for (int i = 0; i < n; i++)
        fprintf(stderr, "%s %s", i ? (i + 1 == n ? " or" : ",") : "", names[i]);
    fprintf(stderr, ", got '%s'\n%s: see '%s --help'\n", value, prog, prog);
    return 0;
}

/* Returns -1 to go on, or an exit code. */
static int parse_args(int argc, char **argv, cli_args *a)
{
    static const struct option longopts[] = {
        {"units", required_argument, 0, OPT_UNITS},
        {"format", required_argument, 0, OPT_FORMAT},
        {"com", required_argument, 0, OPT_COM},
        {"topple", required_argument, 0, OPT_TOPPLE},
        {"epsilon", required_argument, 0, OPT_EPSILON},
        {"pqs-compare", required_argument, 0, OPT_PQS_COMPARE},
        {"pqs-band", required_argument, 0, OPT_PQS_BAND},
        {"ci", required_argument, 0, OPT_CI},
        {"seed", required_argument, 0, OPT_SEED},
        {"mu", required_argument, 0, OPT_MU},
        {"restitution", required_argument, 0, OPT_RESTITUTION},
        {"restitution-law", required_argument, 0, OPT_LAW},
        {"vibration", required_argument, 0, OPT_VIBRATION},
        {"contact-time", required_argument, 0, OPT_CONTACT_TIME},
        {"initial", required_argument, 0, OPT_INITIAL},
        {"scene", required_argument, 0, OPT_SCENE},
        {"trials", required_argument, 0, OPT_TRIALS},
        {"transitions", required_argument, 0, OPT_TRANSITIONS},
        {"engine", required_argument, 0, OPT_ENGINE},
        {"dt", required_argument, 0, OPT_DT},
        {"facets", no_argument, 0, OPT_FACETS},
        {"group", no_argument, 0, OPT_GROUP},
        {"verbose", no_argument, 0, OPT_VERBOSE},
        {"help", no_argument, 0, OPT_HELP},
        {"version", no_argument, 0, OPT_VERSION},
        {0, 0, 0, 0},
    };
    static const char *const formats[] = {"off", "stl", "obj"};
    static const char *const topples[] = {"descent", "edge"};
    static const char *const compares[] = {"raw", "qs"};
    static const char *const bands[] = {"rect", "exact"};
    static const char *const engines[] = {"impulse", "ode", "bullet"};
    memset(a, 0, sizeof *a);
    pd_mesh_read_options_default(&a->read);
    pd_part_options_default(&a->part);
    pd_static_options_default(&a->estimate);
    pd_scene_default(&a->scene);
    pd_sim_options_default(&a->sim);
    opterr = 0;
    int c, code = -1, k;
    double x;
    long n;
    while (code < 0 && (c = getopt_long(argc, argv, ":n:h:v:j:", longopts, NULL)) != -1) {
        switch (c) {
        case OPT_UNITS:
            if (pd_units_parse(optarg, &a->read.units) != PD_OK)
                return fail_usage("--units: expected m, cm, mm or in, got '%s'", optarg);
            break;
        case OPT_FORMAT:
            if (!choose("--format", optarg, formats, 3, &k))
                return EXIT_USAGE;
            a->read.format = (pd_mesh_format)(PD_FORMAT_OFF + k);
            break;
        case OPT_COM:
            if (!parse_vec3(optarg, &a->part.com))
                return fail_usage("--com: expected three finite numbers X,Y,Z, got '%s'", optarg);
            a->part.com_given = 1;
            a->com_text = optarg;
            break;
        case OPT_TOPPLE:
            if (!choose("--topple", optarg, topples, 2, &k))
                return EXIT_USAGE;
            a->estimate.topple = (pd_topple_rule)k;
            break;
        case OPT_EPSILON:
            if (!parse_double(optarg, &x) || x < 0.0 || x > 90.0)
                return fail_usage("--epsilon: expected an angle in degrees from 0 to 90, got '%s'",
                                  optarg);
            a->estimate.epsilon = x * (M_PI / 180.0);
            break;
        case OPT_PQS_COMPARE:
            if (!choose("--pqs-compare", optarg, compares, 2, &k))
                return EXIT_USAGE;
            a->estimate.compare = (pd_pqs_compare)k;
            break;
        case OPT_PQS_BAND:
            if (!choose("--pqs-band", optarg, bands, 2, &k))
                return EXIT_USAGE;
            a->estimate.band = (pd_pqs_band)k;
            break;
        case 'n':
            if (!parse_long(optarg, 1, 1000000000L, &n))
                return fail_usage("-n: expected a number of drops from 1 to 10^9, got '%s'", optarg);
            a->sim.ndrops = n;
            a->dynamic = 1;
            break;
        case OPT_CI:
            if (!parse_double(optarg, &x) || x <= 0.0 || x >= 0.5)
                return fail_usage("--ci: expected a half-width between 0 and 0.5, got '%s'", optarg);
            a->sim.ci_halfwidth = x;
            a->dynamic = 1;
            break;
        case OPT_SEED:
            if (!parse_long(optarg, 0, 0x7fffffffffffffffL, &n))
                return fail_usage("--seed: expected a non-negative integer, got '%s'", optarg);
            a->sim.seed = (uint64_t)n;
            break;
        case 'j':
            if (!parse_long(optarg, 1, 256, &n))
                return fail_usage("-j: expected a number of threads from 1 to 256, got '%s'", optarg);
            a->sim.threads = (int)n;
            break;
        case 'h': code = scene_option(a, "-h", "height", optarg); break;
        case 'v': code = scene_option(a, "-v", "belt_speed", optarg); break;
        case OPT_MU: code = scene_option(a, "--mu", "mu", optarg); break;
        case OPT_RESTITUTION: code = scene_option(a, "--restitution", "restitution", optarg); break;
        case OPT_LAW: code = scene_option(a, "--restitution-law", "restitution_law", optarg); break;
        case OPT_VIBRATION: code = scene_option(a, "--vibration", "vibration", optarg); break;
        case OPT_CONTACT_TIME: code = scene_option(a, "--contact-time", "contact_time", optarg); break;
        case OPT_INITIAL: code = scene_option(a, "--initial", "initial", optarg); break;
        case OPT_SCENE: {
            pd_diag d;
            pd_diag_init(&d);
            pd_status st = pd_scene_read(optarg, &a->scene, &d);
            if (st != PD_OK) {
                fprintf(stderr, "%s: %s\n", prog, d.message);
                return pd_status_is_input_error(st) ? EXIT_USAGE : EXIT_INTERNAL;
            }
            break;
        }
        case OPT_ENGINE:
            if (!choose("--engine", optarg, engines, 3, &k))
                return EXIT_USAGE;
            a->sim.engine = (pd_engine_kind)k;
            break;
        case OPT_DT:
            if (!parse_double(optarg, &x) || x <= 0.0 || x > 0.01)
                return fail_usage("--dt: expected a time step in s, above 0 and at most 0.01, got '%s'",
                                  optarg);
            a->sim.dt = x;
            break;
        case OPT_TRIALS:
            a->trials = optarg;
            a->sim.keep_trials = 1;
            break;
        case OPT_TRANSITIONS:
            a->transitions = optarg;
            break;
        case OPT_FACETS:
            a->facets = 1;
            break;
        case OPT_GROUP:
            a->group = 1;
            break;
        case OPT_VERBOSE:
            a->verbose = 1;
            break;
        case OPT_HELP:
            usage(stdout);
            return 0;
        case OPT_VERSION:
            printf("posedrop %s\n", pd_version());
            return 0;
        case ':':
            return fail_usage("option '%s' needs a value", argv[optind - 1]);
        default:
            return fail_usage("unknown option '%s'", argv[optind - 1]);
        }
    }
    if (code >= 0)
        return code;
    if (optind != argc - 1)
        return fail_usage("%s", optind >= argc ? "expected one PART file" : "expected exactly one PART file");
    if (a->trials && !a->dynamic)
        return fail_usage("%s", "--trials needs drops to record (-n or --ci)");
    int stationary = a->scene.initial == PD_INITIAL_STATIONARY;
    if (a->transitions && (!stationary || !a->dynamic))
        return fail_usage("%s", "--transitions needs the drops of --initial stationary and -n");
    if (stationary && a->sim.ci_halfwidth > 0)
        return fail_usage("%s", "--ci does not go with --initial stationary, which splits a fixed "
                          "number of drops over the poses in advance: give -n");
    if (a->facets && a->dynamic)
        return fail_usage("%s", "--facets lists hull facets; it does not go with -n or --ci");
    if (a->facets && a->group)
        return fail_usage("%s", "--facets lists hull facets; it does not go with --group");
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
    fprintf(stderr, "%s: centre of mass (%.9g, %.9g, %.9g) m%s\n", a->path, part->com.x, part->com.y,
            part->com.z, a->part.com_given ? " (given)" : "");
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

/* What every dynamic run reports, whether or not --verbose: drops that could
 * not be classified and collisions the law had to correct are never silent. */
static void print_sim_summary(const cli_args *a, const pd_sim_result *sim)
{
    if (sim->unsettled)
        fprintf(stderr, "%s: %s: %ld of %ld drops did not settle (time or collision limit) and "
                        "are in no count\n", prog, a->path, sim->unsettled, sim->n);
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
    if (sim->transitions)
        print_stationary_summary(a, sim);
    if (a->verbose && sim->n)
        fprintf(stderr, "%s: %ld drops, %.2f collisions per drop\n", a->path, sim->n,
                (double)sim->collisions / (double)sim->n);
    if (sim->partial)
        fprintf(stderr, "%s: interrupted after %ld drops: results are partial\n", prog, sim->n);
}

static atomic_int interrupted;

static void on_sigint(int sig)
{
    (void)sig;
    atomic_store(&interrupted, 1);
}

int main(int argc, char **argv)
{
    cli_args a;
    int code = parse_args(argc, argv, &a);
    if (code >= 0)
        return code;

    pd_diag diag;
    pd_diag_init(&diag);
    diag.warn = print_warning;
    /* The command offers every engine: it links libposedrop-bullet. */
    pd_status st = pd_bullet_register();
    if (st != PD_OK) {
        fprintf(stderr, "%s: the Bullet engine: %s\n", prog, pd_status_str(st));
        return EXIT_INTERNAL;
    }

    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    pd_sim_result *sim = NULL, *gsim = NULL;
    int *class_of = NULL, nclasses = 0;
    st = pd_mesh_read(a.path, &a.read, &mesh, &diag);
    if (st != PD_OK) {
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    st = pd_part_build(mesh, &a.part, &part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(part, &a.estimate, &res, &diag);
    if (st == PD_OK && a.dynamic) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_sigint;
        sigaction(SIGINT, &sa, NULL);
        a.sim.cancel = &interrupted;
        st = pd_sim_run(part, res, &a.scene, &a.sim, &sim, &diag);
    }
    if (st == PD_OK && a.group) {
        class_of = malloc(sizeof *class_of * (size_t)(res->nposes + 1));
        st = class_of ? pd_pose_classes(part, res, class_of, &nclasses, &diag) : PD_ERR_NOMEM;
        if (st == PD_OK && sim)
            st = pd_sim_result_grouped(sim, class_of, nclasses, &gsim, &diag);
    }
    if (st != PD_OK) {
        code = fail_status(st, &diag, a.path);
        goto done;
    }
    if (a.verbose)
        print_summary(&a, part, res);
    if (sim)
        print_sim_summary(&a, sim);
    if (a.facets)
        print_facets(part, res);
    else if (a.group)
        print_classes(res, gsim, class_of, nclasses);
    else
        print_poses(res, sim);
    code = fflush(stdout) == 0 && !ferror(stdout) ? 0 : EXIT_INTERNAL;
    if (code)
        fprintf(stderr, "%s: error writing the output: %s\n", prog, strerror(errno));
    if (sim && a.trials && !write_trials(a.trials, sim, class_of))
        code = EXIT_INTERNAL;
    if (sim && a.transitions && !write_transitions(a.transitions, gsim ? gsim : sim))
        code = EXIT_INTERNAL;
    if (code == 0 && sim && sim->partial)
        code = EXIT_INTERRUPTED;
done:
    free(class_of);
    pd_sim_result_free(gsim);
    pd_sim_result_free(sim);
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return code;
}
