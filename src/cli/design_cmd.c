/* design_cmd.c: posedrop design, a part changed to land as a target asks
 * (pd_design_run), and what each change moves (pd_design_sensitivity);
 * docs/design.md. */
#include <getopt.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/number.h"
#include "cli/cli.h"

enum { MAX_TARGETS = 64, LINE_MAX_LEN = 4096 };

static void design_usage(FILE *out)
{
    fprintf(out,
        "usage: %s design [options] --vary SPEC (--target CSV | --maximise CSV | --equalise CSV)\n"
        "                 --out OFF PART\n"
        "       %s design [options] --vary SPEC --sensitivity CSV PART\n"
        "\n"
        "Changes a part within ranges so that it lands as asked: each named pose at a\n"
        "probability (--target), the named poses as likely as can be (--maximise), or\n"
        "equally likely (--equalise). Searches the quasi-static model first (QS or PQS,\n"
        "with their exact derivatives), then drops with one seed at every trial part\n"
        "(common random numbers), and checks the result on fresh drops of another seed.\n"
        "Writes the changed part (OFF, in the input's units) and prints one CSV row per\n"
        "named pose:\n"
        "  pose,nx,ny,nz,p_target,p_qs_before,p_pqs_before,p_qs_after,p_pqs_after,\n"
        "  p_refine,p_after,ci_lo,ci_hi,met,vanished,partial\n"
        "p_refine: the search's own drops at the result; p_after, ci_lo, ci_hi: the\n"
        "fresh drops and their 95%% Wilson interval; met: 1 when the target lies in it\n"
        "(targets only); vanished: 1 when the pose's facet no longer rests (it topples,\n"
        "or merged into another); partial: 1 when a signal stopped the drops (the best\n"
        "part found so far, unchecked). stderr: progress, the change in words, the cost.\n"
        "\n"
        "  --vary SPEC      the changes, comma-separated, each KEY=LO:HI:\n"
        "                   scale_x, scale_y, scale_z: stretch the part by a factor\n"
        "                   along its principal axis nearest the file's x, y, z (about\n"
        "                   its centre of mass); stretch_z@A:B=LO:HI: only the slab\n"
        "                   A <= z <= B (file units) along that axis, the rest carried\n"
        "                   along (a flange's thickness); com_x, com_y, com_z: move the\n"
        "                   centre of mass along the axis, in file units (an insert or\n"
        "                   a hollow). e.g. --vary scale_z=0.1:3\n"
        "  --target CSV     columns nx,ny,nz,p: each pose named by the outward normal of\n"
        "                   its resting facet in the file's frame (as posedrop prints\n"
        "                   it), and the probability wanted\n"
        "  --maximise CSV   columns nx,ny,nz: the poses whose summed share to maximise\n"
        "  --equalise CSV   columns nx,ny,nz: the poses to make equally likely\n"
        "  --out OFF        the changed part\n"
        "  --sensitivity CSV  the derivatives of each pose's probability with respect\n"
        "                   to each change at the part as given:\n"
        "                   pose,nx,ny,nz,parameter,d_p_qs,d_p_pqs,d_p,ci_lo,ci_hi,\n"
        "                   step,qs_kink,pqs_kink (per unit factor, or per file unit)\n"
        "  --sensitivity-drops N  drops per side of its paired differences (default\n"
        "                   2000; 0: none)\n"
        "  --model M        pqs (default) or qs: the static model searched first\n"
        "  --group          a pose names its class (the poses the part's rotations\n"
        "                   map onto it)\n"
        "  -n N             drops per evaluation of the refinement (default 20000;\n"
        "                   0: the static answer only)\n"
        "  --max-evals N    refinement evaluations (default 12)\n"
        "  --check N        fresh drops of the result (default 20000; 0: none)\n"
        "  --seed S         the refinement's seed (default 1); the check's is S + 1\n"
        "  --units U        unit of the file's coordinates: m (default), cm, mm, in\n"
        "  --com X,Y,Z      the part's centre of mass in file units (default: uniform)\n"
        "  --epsilon DEG    PQS perturbation angle (default 20)\n"
        "  --scene FILE     the drops' scene ('key = value' lines, as 'posedrop --scene')\n"
        "  -j THREADS       threads (default: all cores); never changes results\n"
        "  --help           this help\n",
        prog, prog);
}

static int dfail(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "%s: design: ", prog);
    fprintf(stderr, fmt, a, b);
    fprintf(stderr, "\n%s: see '%s design --help'\n", prog, prog);
    return EXIT_USAGE;
}

static int number(const char *s, size_t n, double *out)
{
    return n > 0 && pd_parse_double(s, n, out) == PD_NUM_OK;
}

static const char *const axis_names = "xyz";

/* One --vary item into c, lengths in file units scaled by unit. */
static int parse_change(char *item, double unit, pd_change *c)
{
    memset(c, 0, sizeof *c);
    char *eq = strchr(item, '=');
    if (!eq)
        return dfail("--vary: expected KEY=LO:HI, got '%s'%s", item, "");
    *eq = '\0';
    char *range = eq + 1, *colon = strchr(range, ':');
    const char *key = item;
    int kind = -1;
    char *at = strchr(item, '@');
    if (at)
        *at = '\0';
    if (strncmp(key, "scale_", 6) == 0 && !at)
        kind = PD_CHANGE_SCALE;
    else if (strncmp(key, "stretch_", 8) == 0 && at)
        kind = PD_CHANGE_SCALE, c->slab = 1;
    else if (strncmp(key, "com_", 4) == 0 && !at)
        kind = PD_CHANGE_COM;
    const char *ax = strchr(key, '_');
    if (kind < 0 || !ax || strlen(ax) != 2 || !strchr(axis_names, ax[1]) || ax[1] == '\0')
        return dfail("--vary: unknown change '%s': expected scale_x|y|z, stretch_x|y|z@A:B or "
                     "com_x|y|z%s", key, "");
    c->kind = (pd_change_kind)kind;
    c->axis = (int)(strchr(axis_names, ax[1]) - axis_names);
    if (!colon || !number(range, (size_t)(colon - range), &c->lo) ||
        !number(colon + 1, strlen(colon + 1), &c->hi) || !(c->lo < c->hi))
        return dfail("--vary: %s: expected a range LO:HI of two numbers, LO < HI, got '%s'", key,
                     range);
    if (kind == PD_CHANGE_SCALE && !(c->lo > 0.0))
        return dfail("--vary: %s: a factor's range must lie above 0, got '%s'", key, range);
    if (c->slab) {
        char *slab = at + 1, *sc = strchr(slab, ':');
        if (!sc || !number(slab, (size_t)(sc - slab), &c->from) ||
            !number(sc + 1, strlen(sc + 1), &c->to) || !(c->from < c->to))
            return dfail("--vary: %s: expected the slab as @A:B, A < B, got '@%s'", key, slab);
        c->from *= unit;
        c->to *= unit;
    }
    if (kind == PD_CHANGE_COM) {
        c->lo *= unit;
        c->hi *= unit;
    }
    return -1;
}

/* The column index of name in a header line (comma-separated), or -1. */
static int column(const char *header, const char *name)
{
    char buf[LINE_MAX_LEN];
    snprintf(buf, sizeof buf, "%s", header);
    int i = 0;
    for (char *s = strtok(buf, ",\r\n"); s; s = strtok(NULL, ",\r\n"), i++) {
        while (*s == ' ')
            s++;
        size_t n = strlen(s);
        while (n > 0 && s[n - 1] == ' ')
            s[--n] = '\0';
        if (strcmp(s, name) == 0)
            return i;
    }
    return -1;
}

/* Reads the named poses: nx,ny,nz (and p when want_p). */
static int read_targets(const char *path, int want_p, pd_design_target *t, int *nt)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        fprintf(stderr, "%s: design: %s: cannot open it\n", prog, path);
        return 0;
    }
    char line[LINE_MAX_LEN];
    long ln = 0;
    int col[4] = {-1, -1, -1, -1}, ok = 1;
    static const char *const names[4] = {"nx", "ny", "nz", "p"};
    *nt = 0;
    while (ok && fgets(line, sizeof line, f)) {
        ln++;
        if (line[0] == '#' || strspn(line, " \t\r\n") == strlen(line))
            continue;
        if (col[0] < 0) {
            for (int k = 0; k < 4; k++)
                col[k] = column(line, names[k]);
            if (col[0] < 0 || col[1] < 0 || col[2] < 0 || (want_p && col[3] < 0)) {
                fprintf(stderr, "%s: design: %s:%ld: expected a header naming the columns "
                        "nx,ny,nz%s\n", prog, path, ln, want_p ? ",p" : "");
                ok = 0;
            }
            continue;
        }
        if (*nt == MAX_TARGETS) {
            fprintf(stderr, "%s: design: %s:%ld: at most %d poses\n", prog, path, ln, MAX_TARGETS);
            ok = 0;
            break;
        }
        double v[4] = {0, 0, 0, 0};
        int got = 0, i = 0;
        for (char *s = strtok(line, ",\r\n"); s; s = strtok(NULL, ",\r\n"), i++)
            for (int k = 0; k < 4; k++)
                if (col[k] == i) {
                    while (*s == ' ')
                        s++;
                    size_t n = strlen(s);
                    while (n > 0 && s[n - 1] == ' ')
                        n--;
                    if (!number(s, n, &v[k])) {
                        fprintf(stderr, "%s: design: %s:%ld: column %s: expected a number, got "
                                "'%.*s'\n", prog, path, ln, names[k], (int)n, s);
                        ok = 0;
                    }
                    got |= 1 << k;
                }
        if (ok && (got & 7) != 7) {
            fprintf(stderr, "%s: design: %s:%ld: expected values in columns nx,ny,nz%s\n", prog,
                    path, ln, want_p ? ",p" : "");
            ok = 0;
        }
        if (ok && want_p && (!(got & 8) || !(v[3] >= 0.0 && v[3] <= 1.0))) {
            fprintf(stderr, "%s: design: %s:%ld: column p: expected a probability from 0 to 1\n",
                    prog, path, ln);
            ok = 0;
        }
        if (ok && v[0] * v[0] + v[1] * v[1] + v[2] * v[2] == 0.0) {
            fprintf(stderr, "%s: design: %s:%ld: the normal (0, 0, 0) names no pose\n", prog,
                    path, ln);
            ok = 0;
        }
        if (ok)
            t[(*nt)++] = (pd_design_target){{v[0], v[1], v[2]}, v[3]};
    }
    fclose(f);
    if (ok && *nt == 0) {
        fprintf(stderr, "%s: design: %s: no poses listed\n", prog, path);
        ok = 0;
    }
    return ok;
}

/* The CPU time when the design started and when its static stage last
 * reported: the static stage's cost per evaluation. */
static double cpu_start, cpu_static;

static void progress_line(void *user, const char *stage, int evals, double objective)
{
    (void)user;
    if (strcmp(stage, "scan") == 0 || strcmp(stage, "static") == 0)
        cpu_static = cli_cpu_seconds();
    fprintf(stderr, "%s: design: %s: %d evaluation%s, objective %.4g\n", prog, stage, evals,
            evals == 1 ? "" : "s", objective);
}

/* The change as --vary names it (a slab's planes in file units). */
static const char *change_name(const pd_change *c, double unit, char *buf, size_t size)
{
    if (c->slab)
        snprintf(buf, size, "stretch_%c@%g:%g", axis_names[c->axis], c->from / unit, c->to / unit);
    else
        snprintf(buf, size, "%s_%c", c->kind == PD_CHANGE_COM ? "com" : "scale",
                 axis_names[c->axis]);
    return buf;
}

/* The change in words. */
static void say_change(const pd_change *c, double before, double after, double unit,
                       const char *uname)
{
    char name[64];
    change_name(c, unit, name, sizeof name);
    if (c->kind == PD_CHANGE_COM)
        fprintf(stderr, "%s: design: %s = %.10g %s: the centre of mass moved %.4g %s toward %c%c "
                "(range %g:%g)\n", prog, name, after / unit, uname, fabs(after - before) / unit,
                uname, after >= before ? '+' : '-', axis_names[c->axis], c->lo / unit,
                c->hi / unit);
    else if (c->slab)
        fprintf(stderr, "%s: design: %s = %.10g: the slab %g to %g %s along %c %s %.4g%% "
                "(range %g:%g)\n", prog, name, after, c->from / unit, c->to / unit, uname,
                axis_names[c->axis], after >= 1.0 ? "thickened by" : "thinned by",
                100.0 * fabs(after - 1.0), c->lo, c->hi);
    else
        fprintf(stderr, "%s: design: %s = %.10g: the part %s %.4g%% along its axis %c (range "
                "%g:%g)\n", prog, name, after, after >= 1.0 ? "stretched by" : "shortened by",
                100.0 * fabs(after - 1.0), axis_names[c->axis], c->lo, c->hi);
}

/* The library's message, once prefixed with the subcommand. */
static void say_failure(const pd_diag *diag, pd_status st)
{
    const char *m = diag->message[0] ? diag->message : pd_status_str(st);
    fprintf(stderr, "%s: %s%s\n", prog, strncmp(m, "design:", 7) == 0 ? "" : "design: ", m);
}

static int write_off(FILE *f, const pd_part *p, double unit, const char *src, int com_given)
{
    const pd_mesh *m = p->mesh;
    fprintf(f, "# posedrop design: changed from %s\n", src);
    if (com_given)
        fprintf(f, "# centre of mass (give it as --com): %.17g,%.17g,%.17g\n",
                (p->com.x + p->origin.x) / unit, (p->com.y + p->origin.y) / unit,
                (p->com.z + p->origin.z) / unit);
    fprintf(f, "OFF\n%d %d 0\n", m->nverts, m->ntris);
    for (int i = 0; i < m->nverts; i++)
        fprintf(f, "%.17g %.17g %.17g\n", (m->verts[i].x + p->origin.x) / unit,
                (m->verts[i].y + p->origin.y) / unit, (m->verts[i].z + p->origin.z) / unit);
    for (int t = 0; t < m->ntris; t++)
        fprintf(f, "3 %d %d %d\n", m->tris[t][0], m->tris[t][1], m->tris[t][2]);
    return !ferror(f);
}

/* The normal of pose class i's first pose (of pose i without classes). */
static pd_vec3 class_normal(const pd_static_result *res, const int *class_of, int i)
{
    for (int j = 0; j < res->nposes; j++)
        if ((class_of ? class_of[j] : j) == i)
            return res->poses[j].normal;
    return res->poses[0].normal;
}

static void write_sensitivity(FILE *f, const pd_design_sens *s, const pd_static_result *res,
                              const int *class_of, const pd_change *ch, double unit)
{
    fprintf(f, "pose,nx,ny,nz,parameter,d_p_qs,d_p_pqs,d_p,ci_lo,ci_hi,step,qs_kink,pqs_kink\n");
    for (int i = 0; i < s->nposes; i++) {
        pd_vec3 n = class_normal(res, class_of, i);
        for (int k = 0; k < s->nchanges; k++) {
            const pd_design_sens_row *r = &s->rows[i * s->nchanges + k];
            double per = ch[k].kind == PD_CHANGE_COM ? unit : 1.0; /* per file unit */
            char name[64];
            fprintf(f, "%d,%.10g,%.10g,%.10g,%s,%.10g,%.10g,", i + 1, cli_clean(n.x),
                    cli_clean(n.y), cli_clean(n.z), change_name(&ch[k], unit, name, sizeof name),
                    r->d_qs * per, r->d_pqs * per);
            if (s->ndrops > 0)
                fprintf(f, "%.10g,%.10g,%.10g,%.10g", r->d_p * per, r->lo * per, r->hi * per,
                        s->step[k] / per);
            else
                fprintf(f, ",,,");
            fprintf(f, ",%d,%d\n", r->qs_kink, r->pqs_kink);
        }
    }
}

typedef struct design_in {
    const char *path, *com_text, *scene_path, *target_path, *out_path, *sens_path;
    pd_design_goal goal;
    pd_mesh_read_options read;
    pd_part_options po;
    pd_design_options o;
    pd_change changes[PD_DESIGN_MAX_CHANGES];
    int nchanges;
    long sens_drops;
    int goal_given;
} design_in;

static int parse_com(const char *text, double unit, pd_part_options *po)
{
    double v[3];
    const char *s = text;
    for (int k = 0; k < 3; k++) {
        const char *e = strchr(s, k < 2 ? ',' : '\0');
        if (!e || !number(s, (size_t)(e - s), &v[k]))
            return dfail("--com: expected X,Y,Z, got '%s'%s", text, "");
        s = e + 1;
    }
    po->com_given = 1;
    po->com = (pd_vec3){v[0] * unit, v[1] * unit, v[2] * unit};
    return -1;
}

static int parse(int argc, char **argv, design_in *in, char **spec)
{
    enum { D_VARY = 256, D_TARGET, D_MAX, D_EQUAL, D_OUT, D_SENS, D_SENSN, D_MODEL, D_GROUP,
           D_MAXEVALS, D_CHECK, D_SEED, D_UNITS, D_COM, D_EPS, D_SCENE, D_HELP };
    static const struct option longopts[] = {
        {"vary", required_argument, 0, D_VARY}, {"target", required_argument, 0, D_TARGET},
        {"maximise", required_argument, 0, D_MAX}, {"maximize", required_argument, 0, D_MAX},
        {"equalise", required_argument, 0, D_EQUAL}, {"equalize", required_argument, 0, D_EQUAL},
        {"out", required_argument, 0, D_OUT}, {"sensitivity", required_argument, 0, D_SENS},
        {"sensitivity-drops", required_argument, 0, D_SENSN},
        {"model", required_argument, 0, D_MODEL}, {"group", no_argument, 0, D_GROUP},
        {"max-evals", required_argument, 0, D_MAXEVALS}, {"check", required_argument, 0, D_CHECK},
        {"seed", required_argument, 0, D_SEED}, {"units", required_argument, 0, D_UNITS},
        {"com", required_argument, 0, D_COM}, {"epsilon", required_argument, 0, D_EPS},
        {"scene", required_argument, 0, D_SCENE}, {"help", no_argument, 0, D_HELP},
        {0, 0, 0, 0},
    };
    static const char *const units[] = {"m", "cm", "mm", "in"};
    opterr = 0;
    optind = 1;
    int c, code = -1, seed_given = 0;
    while (code < 0 && (c = getopt_long(argc, argv, ":n:j:", longopts, NULL)) != -1) {
        long long v = 0;
        switch (c) {
        case D_VARY:
            if (*spec)
                code = dfail("--vary given twice: list the changes in one%s%s", "", "");
            else if (!(*spec = strdup(optarg)))
                code = EXIT_INTERNAL;
            break;
        case D_TARGET:
        case D_MAX:
        case D_EQUAL:
            if (in->goal_given)
                code = dfail("give one of --target, --maximise, --equalise%s%s", "", "");
            in->goal_given = 1;
            in->target_path = optarg;
            in->goal = c == D_TARGET ? PD_GOAL_TARGET : c == D_MAX ? PD_GOAL_MAXIMISE
                                                                   : PD_GOAL_EQUALISE;
            break;
        case D_OUT: in->out_path = optarg; break;
        case D_SENS: in->sens_path = optarg; break;
        case D_GROUP: in->o.group = 1; break;
        case D_SCENE: in->scene_path = optarg; break;
        case D_COM: in->com_text = optarg; break;
        case D_MODEL:
            if (strcmp(optarg, "qs") == 0)
                in->o.model = PD_DESIGN_QS;
            else if (strcmp(optarg, "pqs") == 0)
                in->o.model = PD_DESIGN_PQS;
            else
                code = dfail("--model: expected qs or pqs, got '%s'%s", optarg, "");
            break;
        case D_UNITS:
            v = -1;
            for (int i = 0; i < 4; i++)
                if (strcmp(optarg, units[i]) == 0)
                    v = i;
            if (v < 0)
                code = dfail("--units: expected m, cm, mm or in, got '%s'%s", optarg, "");
            else
                in->read.units = (pd_units)v;
            break;
        case D_HELP: design_usage(stdout); code = 0; break;
        case D_EPS: {
            pd_num_rule rule = {"a PQS angle in degrees", 0, 0, 90, 0, 0, 0, 0};
            double deg;
            int outcome = pd_num_read(&rule, optarg, &deg, NULL);
            char msg[256];
            if (outcome != PD_NUM_OK)
                code = dfail("--epsilon: %s%s", pd_num_message(msg, sizeof msg, &rule, optarg,
                                                               outcome), "");
            else
                in->o.statics.epsilon = deg * M_PI / 180.0;
            break;
        }
        case 'n':
        case 'j':
        case D_SENSN:
        case D_MAXEVALS:
        case D_CHECK:
        case D_SEED: {
            int zero_ok = c == 'n' || c == D_SENSN || c == D_CHECK || c == D_SEED;
            pd_num_rule rule = {c == 'j' ? "a number of threads" : c == D_SEED ? "a seed"
                                : c == D_MAXEVALS ? "a count" : "a number of drops",
                                1, 0, 0, 0, 0, zero_ok ? 0 : 1,
                                c == 'j' ? 256 : c == D_SEED ? LLONG_MAX - 1 : c == D_MAXEVALS
                                ? 1000 : 100000000};
            int outcome = pd_num_read(&rule, optarg, NULL, &v);
            if (outcome != PD_NUM_OK) {
                char msg[256];
                code = dfail("%s: %s", argv[optind - 1],
                             pd_num_message(msg, sizeof msg, &rule, optarg, outcome));
                break;
            }
            if (c == 'n')
                in->o.sim.ndrops = (long)v;
            else if (c == 'j')
                in->o.sim.threads = (int)v;
            else if (c == D_SENSN)
                in->sens_drops = (long)v;
            else if (c == D_MAXEVALS)
                in->o.max_evals = (int)v;
            else if (c == D_CHECK)
                in->o.check_drops = (long)v;
            else {
                in->o.sim.seed = (uint64_t)v;
                seed_given = 1;
            }
            break;
        }
        case ':': code = dfail("option '%s' needs a value%s", argv[optind - 1], ""); break;
        default: code = dfail("unknown option '%s'%s", argv[optind - 1], ""); break;
        }
    }
    (void)seed_given;
    in->o.check_seed = in->o.sim.seed + 1;
    if (code >= 0)
        return code;
    if (optind + 1 != argc)
        return dfail(optind < argc ? "expected one PART, got '%s' and more%s"
                                   : "expected a PART%s%s", optind < argc ? argv[optind] : "",
                     "");
    in->path = argv[optind];
    if (!*spec)
        return dfail("nothing to change: give --vary KEY=LO:HI[,...]%s%s", "", "");
    if (!in->goal_given && !in->sens_path)
        return dfail("give a goal (--target, --maximise or --equalise) or --sensitivity%s%s", "",
                     "");
    if (in->goal_given && !in->out_path)
        return dfail("--out OFF: the changed part needs a file%s%s", "", "");
    double unit = pd_units_scale(in->read.units);
    for (char *item = strtok(*spec, ","); item; item = strtok(NULL, ",")) {
        if (in->nchanges == PD_DESIGN_MAX_CHANGES)
            return dfail("--vary: at most %s changes%s", "9", "");
        if ((code = parse_change(item, unit, &in->changes[in->nchanges++])) >= 0)
            return code;
    }
    if (in->com_text && (code = parse_com(in->com_text, unit, &in->po)) >= 0)
        return code;
    return -1;
}

/* The part and its poses (and classes). */
static int load(design_in *in, pd_mesh **mesh, pd_part **part, pd_static_result **res,
                int **class_of, int *nclasses)
{
    pd_diag diag;
    pd_diag_init(&diag);
    pd_status st = pd_mesh_read(in->path, &in->read, mesh, &diag);
    if (st == PD_OK)
        st = pd_part_build(*mesh, &in->po, part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(*part, &in->o.statics, res, &diag);
    *nclasses = st == PD_OK ? (*res)->nposes : 0;
    if (st == PD_OK && in->o.group) {
        *class_of = malloc(sizeof **class_of * (size_t)((*res)->nposes + 1));
        st = *class_of ? pd_pose_classes(*part, *res, *class_of, nclasses, &diag) : PD_ERR_NOMEM;
    }
    if (st != PD_OK) {
        cli_say_failure(in->path, st, &diag);
        return 0;
    }
    return 1;
}

static void print_result(const pd_design_result *r, const pd_design_target *t, pd_design_goal goal)
{
    printf("pose,nx,ny,nz,p_target,p_qs_before,p_pqs_before,p_qs_after,p_pqs_after,p_refine,"
           "p_after,ci_lo,ci_hi,met,vanished,partial\n");
    for (int i = 0; i < r->ntargets; i++) {
        const pd_design_target_result *q = &r->targets[i];
        printf("%d,%.10g,%.10g,%.10g,", i + 1, cli_clean(t[i].normal.x), cli_clean(t[i].normal.y),
               cli_clean(t[i].normal.z));
        if (goal == PD_GOAL_MAXIMISE)
            printf(",");
        else
            printf("%.10g,", q->p_target);
        printf("%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,", q->qs_before, q->pqs_before,
               q->qs_after, q->pqs_after, q->p_refine, q->p_after, q->lo, q->hi);
        if (goal == PD_GOAL_MAXIMISE)
            printf(",");
        else
            printf("%d,", q->p_target >= q->lo && q->p_target <= q->hi);
        printf("%d,%d\n", q->vanished, r->partial);
    }
}

static void print_summary(const design_in *in, const pd_design_result *r,
                          const pd_design_target *t, double cpu)
{
    static const char *const unames[] = {"m", "cm", "mm", "in"};
    double unit = pd_units_scale(in->read.units);
    for (int k = 0; k < r->nchanges; k++)
        say_change(&in->changes[k], r->value_before[k], r->value[k], unit,
                   unames[in->read.units]);
    for (int k = 0; k < r->nchanges; k++) {
        char name[64];
        fprintf(stderr, "%s: design: %s: %.6g at the %s optimum, %.6g after the drops\n", prog,
                change_name(&in->changes[k], unit, name, sizeof name),
                in->changes[k].kind == PD_CHANGE_COM ? r->value_static[k] / unit
                                                     : r->value_static[k],
                in->o.model == PD_DESIGN_QS ? "QS" : "PQS",
                in->changes[k].kind == PD_CHANGE_COM ? r->value[k] / unit : r->value[k]);
    }
    for (int i = 0; i < r->ntargets; i++) {
        const pd_design_target_result *q = &r->targets[i];
        if (q->appeared)
            fprintf(stderr, "%s: design: pose %d (%.3g, %.3g, %.3g) does not rest on the part as "
                    "given: it appears as the part changes\n", prog, i + 1, t[i].normal.x,
                    t[i].normal.y, t[i].normal.z);
        if (q->vanished)
            fprintf(stderr, "%s: design: pose %d (%.3g, %.3g, %.3g) does not rest on the result: "
                    "its facet topples (or merged into another)\n", prog, i + 1, t[i].normal.x,
                    t[i].normal.y, t[i].normal.z);
    }
    if (r->poses_after != r->poses_before)
        fprintf(stderr, "%s: design: the part rests in %d poses as given, %d after the change\n",
                prog, r->poses_before, r->poses_after);
    fprintf(stderr, "%s: design: objective: static %.4g, refinement drops %.4g, fresh drops %.4g\n",
            prog, r->objective_static, r->objective_refine, r->objective_after);
    fprintf(stderr, "%s: design: cost: %d static evaluations (%.3g ms CPU each), %d drop "
            "evaluations, %ld drops; %.2f s CPU in all (CPU, not wall: wall time depends on the "
            "machine's load)\n", prog, r->static_evals,
            1e3 * (cpu_static - cpu_start) / (r->static_evals > 0 ? r->static_evals : 1),
            r->drop_evals, r->drops, cpu);
}

/* One sentence per pose and change: what a small change does. */
static void say_sensitivity(const pd_design_sens *s, const pd_static_result *res,
                            const int *class_of, const pd_change *ch, double unit,
                            const char *uname)
{
    for (int i = 0; i < s->nposes; i++) {
        pd_vec3 n = class_normal(res, class_of, i);
        for (int k = 0; k < s->nchanges; k++) {
            const pd_design_sens_row *r = &s->rows[i * s->nchanges + k];
            double per = ch[k].kind == PD_CHANGE_COM ? unit : 0.1;
            char what[96];
            if (ch[k].kind == PD_CHANGE_COM)
                snprintf(what, sizeof what, "moving the centre of mass 1 %s toward +%c", uname,
                         axis_names[ch[k].axis]);
            else if (ch[k].slab)
                snprintf(what, sizeof what, "stretching the slab %g to %g %s along %c by 10%%",
                         ch[k].from / unit, ch[k].to / unit, uname, axis_names[ch[k].axis]);
            else
                snprintf(what, sizeof what, "stretching the part along %c by 10%%",
                         axis_names[ch[k].axis]);
            fprintf(stderr, "%s: design: pose %d (%.3g, %.3g, %.3g): %s moves it %+.2f points "
                    "(QS), %+.2f (PQS)", prog, i + 1, cli_clean(n.x), cli_clean(n.y),
                    cli_clean(n.z), what, 100 * r->d_qs * per, 100 * r->d_pqs * per);
            if (s->ndrops > 0)
                fprintf(stderr, ", %+.2f [%+.2f, %+.2f] (drops)", 100 * r->d_p * per,
                        100 * r->lo * per, 100 * r->hi * per);
            fprintf(stderr, "%s\n", r->qs_kink || r->pqs_kink ? "; at a kink of the static "
                    "model (one-sided)" : "");
        }
    }
}

int cli_design(int argc, char **argv)
{
    if (!cli_writer())
        return 0;
    design_in in;
    memset(&in, 0, sizeof in);
    pd_mesh_read_options_default(&in.read);
    pd_part_options_default(&in.po);
    pd_design_options_default(&in.o);
    in.sens_drops = 2000;
    char *spec = NULL;
    int code = parse(argc, argv, &in, &spec);
    pd_diag diag;
    pd_diag_init(&diag);
    if (code < 0 && pd_bullet_register() != PD_OK) {
        fprintf(stderr, "%s: the Bullet engine could not be registered\n", prog);
        code = EXIT_INTERNAL;
    }
    if (code < 0 && in.scene_path && pd_scene_read(in.scene_path, &in.o.scene, &diag) != PD_OK) {
        fprintf(stderr, "%s: %s\n", prog, diag.message);
        code = EXIT_USAGE;
    }
    pd_design_target targets[MAX_TARGETS];
    int nt = 0;
    if (code < 0 && in.goal_given &&
        !read_targets(in.target_path, in.goal == PD_GOAL_TARGET, targets, &nt))
        code = EXIT_USAGE;
    cli_file files[5];
    int nfiles = 0;
    files[nfiles++] = (cli_file){"PART", in.path, 0, 0};
    if (in.target_path)
        files[nfiles++] = (cli_file){"target", in.target_path, 0, 1};
    if (in.scene_path)
        files[nfiles++] = (cli_file){"scene", in.scene_path, 0, 1};
    if (in.out_path)
        files[nfiles++] = (cli_file){"out", in.out_path, 1, 1};
    if (in.sens_path)
        files[nfiles++] = (cli_file){"sensitivity", in.sens_path, 1, 1};
    if (code < 0 && !cli_files_apart(files, nfiles))
        code = EXIT_USAGE;
    out_file outs[2] = {{0}};
    if (code < 0 && in.out_path && !out_open(&outs[0], in.out_path))
        code = EXIT_USAGE;
    if (code < 0 && in.sens_path && !out_open(&outs[1], in.sens_path))
        code = EXIT_USAGE;
    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *res = NULL;
    int *class_of = NULL, nclasses = 0;
    if (code < 0 && !load(&in, &mesh, &part, &res, &class_of, &nclasses))
        code = EXIT_USAGE;
    static const char *const unames[] = {"m", "cm", "mm", "in"};
    double unit = pd_units_scale(in.read.units);
    signals_catch(&in.o.sim);
    if (code < 0 && in.sens_path) {
        pd_design_sens *s = NULL;
        pd_sim_options so = in.o.sim;
        so.ndrops = in.sens_drops;
        double c0 = cli_cpu_seconds();
        pd_status st = pd_design_sensitivity(part, res, &in.o.statics, in.changes, in.nchanges,
                                             class_of, nclasses, &in.o.scene,
                                             in.sens_drops > 0 ? &so : NULL, &s, &diag);
        if (st != PD_OK) {
            say_failure(&diag, st);
            code = st == PD_ERR_USAGE ? EXIT_USAGE : EXIT_INTERNAL;
        } else {
            write_sensitivity(outs[1].f, s, res, class_of, in.changes, unit);
            say_sensitivity(s, res, class_of, in.changes, unit, unames[in.read.units]);
            fprintf(stderr, "%s: design: sensitivities: %.2f s CPU\n", prog,
                    cli_cpu_seconds() - c0);
            if (!(out_close(&outs[1]) && out_place(&outs[1])))
                code = EXIT_INTERNAL;
        }
        pd_design_sens_free(s);
    }
    if (code < 0 && in.goal_given) {
        in.o.progress = progress_line;
        pd_design_result *r = NULL;
        double c0 = cli_cpu_seconds();
        cpu_start = cpu_static = c0;
        pd_status st = pd_design_run(part, in.changes, in.nchanges, in.goal, targets, nt, &in.o,
                                     &r, &diag);
        if (st != PD_OK) {
            say_failure(&diag, st);
            code = st == PD_ERR_USAGE || pd_status_is_input_error(st) ? EXIT_USAGE
                                                                      : EXIT_INTERNAL;
        } else {
            int com_moved = in.po.com_given;
            for (int k = 0; k < in.nchanges; k++)
                com_moved |= in.changes[k].kind == PD_CHANGE_COM;
            if (!write_off(outs[0].f, r->part, unit, in.path, com_moved) ||
                !(out_close(&outs[0]) && out_place(&outs[0])))
                code = EXIT_INTERNAL;
            else {
                print_summary(&in, r, targets, cli_cpu_seconds() - c0);
                if (com_moved)
                    fprintf(stderr, "%s: design: %s carries its centre of mass in a comment: "
                            "drop it with --com %.10g,%.10g,%.10g\n", prog, in.out_path,
                            (r->part->com.x + r->part->origin.x) / unit,
                            (r->part->com.y + r->part->origin.y) / unit,
                            (r->part->com.z + r->part->origin.z) / unit);
                if (r->partial)
                    fprintf(stderr, "%s: design: interrupted: %s holds the best part found "
                            "before the signal, neither refined further nor checked\n", prog,
                            in.out_path);
                print_result(r, targets, in.goal);
                if (fflush(stdout) != 0 || ferror(stdout))
                    code = EXIT_INTERNAL;
            }
        }
        pd_design_result_free(r);
    }
    for (int k = 0; k < 2; k++)
        out_abort(&outs[k]);
    free(class_of);
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(mesh);
    free(spec);
    if (code < 0)
        code = signals_caught() ? cli_interrupt_code() : 0;
    return code;
}
