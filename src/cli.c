/* cli.c: the posedrop command, a thin client of libposedrop.
 *
 * It only parses arguments, calls the library and prints: the results as CSV
 * on stdout, diagnostics on stderr. Exit codes: 0 success, 2 bad usage or
 * input (nothing is printed on stdout), 1 internal failure. */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "posedrop/posedrop.h"

enum { EXIT_USAGE = 2, EXIT_INTERNAL = 1 };

static const char *prog = "posedrop";

static void usage(FILE *out)
{
    fprintf(out,
        "usage: %s [options] PART\n"
        "\n"
        "Predicts the probability of each stable pose of a rigid part dropped on a\n"
        "flat surface, by the quasi-static (QS) and perturbed quasi-static (PQS)\n"
        "estimators, and prints one CSV row per stable pose:\n"
        "  pose,nx,ny,nz,area,height,p_qs,p_pqs\n"
        "pose: 1 = most probable (QS); nx,ny,nz: outward unit normal of the resting\n"
        "facet in the file's frame (gravity's direction in the part's frame); area:\n"
        "facet area in m^2; height: centre of mass above the floor in m.\n"
        "\n"
        "PART is an OFF, STL (ASCII or binary) or OBJ file.\n"
        "\n"
        "options:\n"
        "  --units U          unit of the file's coordinates: m (default), cm, mm, in\n"
        "  --format F         off, stl or obj (default: detect from content and name)\n"
        "  --com X,Y,Z        centre of mass in the file's units (default: computed\n"
        "                     from the mesh, uniform density); required for meshes\n"
        "                     that are not closed\n"
        "  --topple RULE      descent (default): exact quasi-static motion, steepest\n"
        "                     descent of the centre of mass, which may end on a facet\n"
        "                     sharing only a vertex; edge: the paper's graph between\n"
        "                     edge-adjacent facets\n"
        "  --epsilon DEG      PQS perturbation angle in degrees, 0..90 (default 20)\n"
        "  --pqs-compare C    raw (default): transfer when the facet's solid-angle\n"
        "                     probability is lower; qs: compare propagated QS values\n"
        "  --pqs-band B       rect (default): the paper's |a| x epsilon band clipped\n"
        "                     to its triangle; exact: exact spherical band area\n"
        "  --facets           one row per hull facet instead of per pose, with its\n"
        "                     stability and quasi-static successor\n"
        "  -v, --verbose      a summary of the part on stderr\n"
        "  --help             this help\n"
        "  --version          version\n"
        "\n"
        "exit status: 0 success, 2 bad usage or input, 1 internal failure\n",
        prog);
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

static void print_poses(const pd_static_result *res)
{
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs\n");
    for (int i = 0; i < res->nposes; i++) {
        const pd_pose *p = &res->poses[i];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n", i + 1, clean(p->normal.x),
               clean(p->normal.y), clean(p->normal.z), p->area, p->height, clean(p->p_qs),
               clean(p->p_pqs));
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

typedef struct {
    const char *path;
    pd_mesh_read_options read;
    pd_part_options part;
    const char *com_text;
    pd_static_options estimate;
    int facets, verbose;
} cli_args;

enum { OPT_UNITS = 256, OPT_FORMAT, OPT_COM, OPT_TOPPLE, OPT_EPSILON, OPT_PQS_COMPARE,
       OPT_PQS_BAND, OPT_FACETS, OPT_HELP, OPT_VERSION };

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
        {"facets", no_argument, 0, OPT_FACETS},
        {"verbose", no_argument, 0, 'v'},
        {"help", no_argument, 0, OPT_HELP},
        {"version", no_argument, 0, OPT_VERSION},
        {0, 0, 0, 0},
    };
    memset(a, 0, sizeof *a);
    pd_mesh_read_options_default(&a->read);
    pd_part_options_default(&a->part);
    pd_static_options_default(&a->estimate);
    opterr = 0;
    int c;
    double deg;
    while ((c = getopt_long(argc, argv, ":v", longopts, NULL)) != -1) {
        switch (c) {
        case OPT_UNITS:
            if (pd_units_parse(optarg, &a->read.units) != PD_OK)
                return fail_usage("--units: expected m, cm, mm or in, got '%s'", optarg);
            break;
        case OPT_FORMAT:
            if (strcmp(optarg, "off") == 0)
                a->read.format = PD_FORMAT_OFF;
            else if (strcmp(optarg, "stl") == 0)
                a->read.format = PD_FORMAT_STL;
            else if (strcmp(optarg, "obj") == 0)
                a->read.format = PD_FORMAT_OBJ;
            else
                return fail_usage("--format: expected off, stl or obj, got '%s'", optarg);
            break;
        case OPT_COM:
            if (!parse_vec3(optarg, &a->part.com))
                return fail_usage("--com: expected three finite numbers X,Y,Z, got '%s'", optarg);
            a->part.com_given = 1;
            a->com_text = optarg;
            break;
        case OPT_TOPPLE:
            if (strcmp(optarg, "descent") == 0)
                a->estimate.topple = PD_TOPPLE_DESCENT;
            else if (strcmp(optarg, "edge") == 0)
                a->estimate.topple = PD_TOPPLE_EDGE;
            else
                return fail_usage("--topple: expected descent or edge, got '%s'", optarg);
            break;
        case OPT_EPSILON:
            if (!parse_double(optarg, &deg) || deg < 0.0 || deg > 90.0)
                return fail_usage("--epsilon: expected an angle in degrees from 0 to 90, got '%s'",
                                  optarg);
            a->estimate.epsilon = deg * (M_PI / 180.0);
            break;
        case OPT_PQS_COMPARE:
            if (strcmp(optarg, "raw") == 0)
                a->estimate.compare = PD_PQS_COMPARE_RAW;
            else if (strcmp(optarg, "qs") == 0)
                a->estimate.compare = PD_PQS_COMPARE_QS;
            else
                return fail_usage("--pqs-compare: expected raw or qs, got '%s'", optarg);
            break;
        case OPT_PQS_BAND:
            if (strcmp(optarg, "rect") == 0)
                a->estimate.band = PD_PQS_BAND_RECT;
            else if (strcmp(optarg, "exact") == 0)
                a->estimate.band = PD_PQS_BAND_EXACT;
            else
                return fail_usage("--pqs-band: expected rect or exact, got '%s'", optarg);
            break;
        case OPT_FACETS:
            a->facets = 1;
            break;
        case 'v':
            a->verbose = 1;
            break;
        case OPT_HELP:
            usage(stdout);
            return 0;
        case OPT_VERSION:
            printf("posedrop %s\n", PD_VERSION_STRING);
            return 0;
        case ':':
            return fail_usage("option '%s' needs a value", argv[optind - 1]);
        default:
            return fail_usage("unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind != argc - 1)
        return fail_usage("%s", optind >= argc ? "expected one PART file" : "expected exactly one PART file");
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

int main(int argc, char **argv)
{
    cli_args a;
    int code = parse_args(argc, argv, &a);
    if (code >= 0)
        return code;

    pd_diag diag;
    pd_diag_init(&diag);
    diag.warn = print_warning;

    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    pd_status st = pd_mesh_read(a.path, &a.read, &mesh, &diag);
    if (st != PD_OK) {
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    st = pd_part_build(mesh, &a.part, &part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(part, &a.estimate, &res, &diag);
    if (st != PD_OK) {
        code = fail_status(st, &diag, a.path);
    } else {
        if (a.verbose)
            print_summary(&a, part, res);
        if (a.facets)
            print_facets(part, res);
        else
            print_poses(res);
        code = fflush(stdout) == 0 && !ferror(stdout) ? 0 : EXIT_INTERNAL;
        if (code)
            fprintf(stderr, "%s: error writing the output: %s\n", prog, strerror(errno));
    }
done:
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return code;
}
