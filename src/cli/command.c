/* command.c: the run after its options, whoever parsed them (the posedrop
 * command, cli.c, or its merge subcommand, merge.c): read the part,
 * estimate, drop (or sum the shards), and print the CSV (or JSON) on
 * stdout, the side files and pictures, diagnostics on stderr. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include "cli/cli.h"
#include "cli/command.h"

static void print_warning(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "%s: warning: %s\n", prog, message);
}

/* --crosscheck's columns (xe NULL: none): each engine's p (empty for an
 * engine an interruption kept from running), their lowest and highest, and
 * whether two engines' intervals are apart. */
static void print_spread_header(const viz_engines *xe)
{
    if (xe)
        printf(",p_impulse,p_ode,p_bullet,p_engine_min,p_engine_max,engines_disagree");
}

static void print_spread(const viz_engines *xe, int row)
{
    if (!xe)
        return;
    for (int k = 0; k < VIZ_ENGINES; k++) {
        const pd_sim_result *r = xe->sim[k];
        if (r && r->n > 0)
            printf(",%.10g", r->p[row]);
        else
            printf(",");
    }
    viz_spread x = viz_engine_spread(xe, row);
    printf(",%.10g,%.10g,%d", x.lo, x.hi, x.apart);
}

/* A stationary shard adds the counts its merge needs to estimate the chain:
 * first (uniform drops settled in the row's pose) and to_J (drops started
 * resting on the row's pose that settled in pose J). */
static void print_poses(const pd_static_result *res, const pd_sim_result *sim,
                        const viz_engines *xe)
{
    int chain = sim && sim->nshards > 0 && sim->transitions;
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs%s%s",
           sim ? ",n,count,p,ci_lo,ci_hi,unsettled,partial" : "", chain ? ",first" : "");
    print_spread_header(xe);
    for (int j = 0; chain && j < res->nposes; j++)
        printf(",to_%d", j + 1);
    printf("\n");
    for (int i = 0; i < res->nposes; i++) {
        const pd_pose *p = &res->poses[i];
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", i + 1, cli_clean(p->normal.x),
               cli_clean(p->normal.y), cli_clean(p->normal.z), p->area, p->height, cli_clean(p->p_qs),
               cli_clean(p->p_pqs));
        if (sim)
            printf(",%ld,%ld,%.10g,%.10g,%.10g,%ld,%d", sim->n, sim->count[i], sim->p[i],
                   sim->ci_lo[i], sim->ci_hi[i], sim->unsettled, sim->partial);
        for (int j = -1; chain && j < res->nposes; j++)
            printf(",%ld", j < 0 ? sim->first_count[i]
                                 : sim->transitions[(size_t)i * (size_t)res->nposes + (size_t)j]);
        print_spread(xe, i);
        printf("\n");
    }
}

/* One row per class: the columns of print_poses, the first member's geometry,
 * probabilities summed (gsim holds the library's grouped counts and
 * intervals), and the members' pose numbers. */
static void print_classes(const pd_static_result *res, const pd_sim_result *gsim,
                          const int *class_of, int nclasses, const viz_engines *xe)
{
    printf("pose,nx,ny,nz,area,height,p_qs,p_pqs%s", gsim ? ",n,count,p,ci_lo,ci_hi,unsettled,partial" : "");
    print_spread_header(xe);
    printf(",members\n");
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
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g", c + 1, cli_clean(p->normal.x),
               cli_clean(p->normal.y), cli_clean(p->normal.z), p->area, p->height, cli_clean(qs),
               cli_clean(pqs));
        if (gsim)
            printf(",%ld,%ld,%.10g,%.10g,%.10g,%ld,%d", gsim->n, gsim->count[c], gsim->p[c],
                   gsim->ci_lo[c], gsim->ci_hi[c], gsim->unsettled, gsim->partial);
        print_spread(xe, c);
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
        printf("%d,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%d,%d,%d,%d,%d\n", f + 1, cli_clean(n.x),
               cli_clean(n.y), cli_clean(n.z), r->area, r->height, r->p_raw, r->stable, r->knife,
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

/* A side file (--trials, --transitions; out_file in cli.h, shared with
 * posedrop fit). It is made ready before any work,
 * so that a path that cannot be written fails at once (exit 2, nothing on
 * stdout). A regular file, or one that does not exist yet, is written to a
 * temporary file in its directory and renamed onto its path only once every
 * byte is written: a failed or interrupted run never leaves a truncated file
 * that looks like a result, nor destroys the one it would replace. Anything
 * else (a device such as /dev/stdout, a pipe) is opened and written as it
 * is; a write error there (/dev/full) is caught when it is closed. */
static int out_fail(const char *path, const char *why)
{
    fprintf(stderr, "%s: %s: cannot write: %s\n", prog, path, why);
    return 0;
}

void cli_say_failure(const char *path, pd_status st, const pd_diag *diag)
{
    const char *msg = diag->message[0] ? diag->message : pd_status_str(st);
    if (strncmp(msg, path, strlen(path)) == 0)
        fprintf(stderr, "%s: %s\n", prog, msg);
    else
        fprintf(stderr, "%s: %s: %s\n", prog, path, msg);
}

int out_open(out_file *o, const char *path)
{
    memset(o, 0, sizeof *o);
    o->path = path;
    if (!*path)
        return out_fail("''", "an empty file name");
    struct stat sb;
    int exists = stat(path, &sb) == 0;
    if (exists && S_ISDIR(sb.st_mode))
        return out_fail(path, "is a directory");
    if (exists && S_ISFIFO(sb.st_mode)) {
        /* open(2) of a named pipe waits for a reader, for ever if none
         * comes, and no signal then stops the run as it should: one with
         * no reader yet is refused at once. */
        int fd = open(path, O_WRONLY | O_NONBLOCK | O_CLOEXEC);
        if (fd < 0)
            return out_fail(path, errno == ENXIO ? "a named pipe that no program is reading"
                                                 : strerror(errno));
        int flags = fcntl(fd, F_GETFL);
        if (flags < 0 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0 ||
            !(o->f = fdopen(fd, "w"))) {
            int err = errno;
            close(fd);
            return out_fail(path, strerror(err));
        }
        return 1;
    }
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
void out_abort(out_file *o)
{
    if (o->f)
        fclose(o->f);
    if (o->tmp)
        unlink(o->tmp);
    free(o->tmp);
    free(o->target);
    memset(o, 0, sizeof *o);
}

/* Closes with every write error caught; the temporary stays until
 * out_place (or out_abort). Does nothing when the file is closed already. */
int out_close(out_file *o)
{
    if (!o->f)
        return 1;
    errno = 0;
    int ok = fflush(o->f) == 0 && !ferror(o->f);
    int err = errno;
    if (fclose(o->f) != 0 && ok) {
        ok = 0;
        err = errno;
    }
    o->f = NULL;
    if (!ok) {
        fprintf(stderr, "%s: %s: write error: %s\n", prog, o->path, strerror(err ? err : EIO));
        out_abort(o);
    }
    return ok;
}

/* Puts a closed file in place. */
int out_place(out_file *o)
{
    int ok = 1;
    if (o->tmp && rename(o->tmp, o->target) != 0) {
        fprintf(stderr, "%s: %s: cannot put it in place: %s\n", prog, o->path, strerror(errno));
        ok = 0;
    } else {
        free(o->tmp);
        o->tmp = NULL;
    }
    out_abort(o);
    return ok;
}

int out_place_all(out_file *const *files, int n)
{
    int ok = 1;
    for (int i = 0; i < n; i++)
        if (files[i]->path)
            ok &= out_place(files[i]);
    return ok;
}

/* --trace: one row per state of the traced drop, in full precision; called
 * from the thread that runs that drop, the only writer of the file while
 * the drops run. */
static void write_trace_row(void *user, const pd_trace_row *r)
{
    fprintf((FILE *)user,
            "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
            "%.17g,%.17g,%d,%s\n",
            r->t, r->x[0], r->x[1], r->x[2], r->q[0], r->q[1], r->q[2], r->q[3], r->v[0], r->v[1],
            r->v[2], r->w[0], r->w[1], r->w[2], r->energy, r->depth, r->contacts, r->event);
}

/* One row per drop. With --group (class_of not NULL) the pose column holds
 * the class number, as in the main output, so the two files join on it; the
 * pose within the class follows in a column member. An unsettled drop has
 * pose (and member) 0. The last column, partial, is 1 in every row of an
 * interrupted run (its file holds only the drops done), as in the main
 * output. */
static void write_trials(FILE *f, const pd_sim_result *sim, const int *class_of,
                         const pd_scene *scene, int partial)
{
    fprintf(f, "drop,qw,qx,qy,qz,pose,collisions,time,end%s", class_of ? ",member" : "");
    for (int k = 0; k < PD_NPARAMS; k++)
        if (pd_scene_varies(scene, (pd_scene_param)k))
            fprintf(f, ",%s", pd_scene_param_name((pd_scene_param)k));
    fprintf(f, ",partial\n");
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
            if (pd_scene_varies(scene, (pd_scene_param)k))
                fprintf(f, ",%.17g", t->param[k] / (k == PD_PARAM_VIBRATION ? M_PI / 180.0 : 1.0));
        fprintf(f, ",%d\n", partial);
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
 * parameter, numbered as in the output: the effect first, then the thirds
 * it comes from, the index, and an interaction where one is flagged (its
 * columns empty where none is); partial as in --trials. */
static void write_sensitivity(FILE *f, const pd_sensitivity *s, int partial)
{
    fprintf(f, "pose,parameter,effect,effect_lo,effect_hi,n_low,p_low,p_low_lo,p_low_hi,n_high,"
               "p_high,p_high_lo,p_high_hi,index,index_lo,index_hi,interacts,effect_in_low,"
               "effect_in_middle,effect_in_high,interaction,interaction_lo,interaction_hi,partial\n");
    for (int i = 0; i < s->nposes * s->nparams; i++) {
        const pd_sensitivity_row *r = &s->rows[i];
        fprintf(f, "%d,%s,%.6g,%.6g,%.6g,%ld,%.10g,%.10g,%.10g,%ld,%.10g,%.10g,%.10g,%.6g,%.6g,"
                   "%.6g,", r->pose + 1, pd_scene_param_name(r->param), r->effect, r->effect_lo,
                r->effect_hi, r->n_low, r->p_low, r->p_low_lo, r->p_low_hi, r->n_high, r->p_high,
                r->p_high_lo, r->p_high_hi, r->index, r->index_lo, r->index_hi);
        if (r->interacts >= 0)
            fprintf(f, "%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d\n",
                    pd_scene_param_name((pd_scene_param)r->interacts), r->effect_in[0],
                    r->effect_in[1], r->effect_in[2], r->interaction, r->interaction_lo,
                    r->interaction_hi, partial);
        else
            fprintf(f, ",,,,,,,%d\n", partial);
    }
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
    /* p is count / n, so the rows' p no longer sum to 1: said with the
     * count (a stationary run's p is the chain's, which does). */
    char sum[64] = "";
    if (!sim->transitions && sim->n > 0)
        snprintf(sum, sizeof sum, " (p sums to %.4g, not 1)",
                 (double)(sim->n - sim->unsettled) / (double)sim->n);
    if (sim->time_limited + sim->collision_limited + sim->failed != sim->unsettled) {
        fprintf(stderr, "%s: %s: %ld of %ld drops did not settle (time or collision limit, or "
                        "a solver failed) and are in no count%s\n", prog, a->path,
                sim->unsettled, sim->n, sum);
        return;
    }
    fprintf(stderr, "%s: %s: %ld of %ld drops did not settle and are in no count%s:", prog,
            a->path, sim->unsettled, sim->n, sum);
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

/* --crosscheck: the drops on the other engines, from the same seed, so that
 * drop i starts from the same state on each; xsim[k] for engine k, the
 * main run's own slot left NULL. A signal stops it: the engines not yet run
 * stay NULL. ODE and Bullet take --dt when given; the impulse engine has no
 * step. Only the main run keeps its drops' records (--trials,
 * --sensitivity). */
static pd_status crosscheck_run(const pd_part *part, const pd_static_result *res, cli_args *a,
                                pd_sim_result *xsim[VIZ_ENGINES], pd_diag *diag)
{
    pd_sim_options main_run = a->sim;
    pd_status st = PD_OK;
    for (int k = 0; k < VIZ_ENGINES && st == PD_OK; k++) {
        if (k == (int)main_run.engine)
            continue;
        if (cli_any(signals_caught()))
            break;
        a->sim.engine = (pd_engine_kind)k;
        a->sim.dt = k == PD_ENGINE_IMPULSE ? 0.0 : main_run.dt;
        a->sim.keep_trials = 0;
        /* --trace records --engine's drop only. */
        a->sim.trace = NULL;
        st = cli_simulate(part, res, a, &xsim[k], diag);
    }
    a->sim = main_run;
    return st;
}

/* --crosscheck in words on stderr, always: whether the engines' 95%
 * intervals are apart on any pose (class), and where. */
static void print_crosscheck(const cli_args *a, const viz_engines *xe, int n, int grouped)
{
    const char *what = grouped ? "class" : "pose";
    int apart = 0, ran = 0, widest = 0;
    double wide = -1.0;
    for (int k = 0; k < VIZ_ENGINES; k++)
        ran += xe->sim[k] && xe->sim[k]->n > 0;
    for (int i = 0; i < n; i++) {
        viz_spread x = viz_engine_spread(xe, i);
        apart += x.apart;
        if (x.hi - x.lo > wide) {
            wide = x.hi - x.lo;
            widest = i;
        }
    }
    if (ran < VIZ_ENGINES)
        fprintf(stderr, "%s: %s: crosscheck: %d of %d engines ran before the interruption\n",
                prog, a->path, ran, VIZ_ENGINES);
    if (ran < 2)
        return;
    if (!apart) {
        fprintf(stderr, "%s: %s: crosscheck: the engines agree within their 95%% intervals on "
                        "every %s (widest range %.1f points, %s %d)\n", prog, a->path, what,
                100.0 * wide, what, widest + 1);
        return;
    }
    fprintf(stderr, "%s: %s: crosscheck: the engines disagree beyond their 95%% intervals on "
                    "%d of %d %s%s:", prog, a->path, apart, n, what,
            n == 1 ? "" : grouped ? "es" : "s");
    for (int i = 0, sep = 0; i < n; i++) {
        viz_spread x = viz_engine_spread(xe, i);
        if (!x.apart)
            continue;
        fprintf(stderr, "%s %s %d (", sep++ ? ";" : "", what, i + 1);
        for (int k = 0, c = 0; k < VIZ_ENGINES; k++)
            if (xe->sim[k] && xe->sim[k]->n > 0)
                fprintf(stderr, "%s%s %.1f%%", c++ ? ", " : "", viz_engine_label(k),
                        100.0 * xe->sim[k]->p[i]);
        fprintf(stderr, ")");
    }
    fprintf(stderr, "; there the contact model limits the estimate, not the number of drops "
                    "(p_engine_min, p_engine_max)\n");
}

double cli_wall_seconds(void)
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
    out_file trials_out = {0}, transitions_out = {0}, sens_out = {0}, trace_out = {0},
             pic_out[VIZ_KINDS] = {{0}};
    int opened = (!a->trials || out_open(&trials_out, a->trials)) &&
                 (!a->trace || out_open(&trace_out, a->trace)) &&
                 (!a->transitions || out_open(&transitions_out, a->transitions)) &&
                 (!a->sensitivity || out_open(&sens_out, a->sensitivity));
    for (int k = 0; k < VIZ_KINDS && opened; k++)
        opened = !a->pictures[k] || out_open(&pic_out[k], a->pictures[k]);
    /* A measured distribution is read before the work too. */
    viz_measured *measured = NULL;
    double t0 = cli_wall_seconds(), t_static = 0.0, t_sim = 0.0;
    if (opened && a->measured && (st = viz_measured_read(a->measured, &measured, &diag)) != PD_OK) {
        fail_status(st, &diag, NULL);
        opened = 0;
    }
    if (!opened) {
        out_abort(&trials_out);
        out_abort(&trace_out);
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
    pd_sim_result *xsim[VIZ_ENGINES] = {NULL}, *xgsim[VIZ_ENGINES] = {NULL};
    viz_engines xe_store, *xe = NULL;
    pd_sensitivity *sens = NULL;
    int *class_of = NULL, nclasses = 0;
    signals_catch_static(a);
    static_progress_begin(&a->part);
    st = pd_mesh_read(a->path, &a->read, &mesh, &diag);
    if (st != PD_OK && st != PD_ERR_CANCELLED) {
        static_progress_end();
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    /* The part takes the file's mesh: two copies of a large one would be
     * held through the whole build. */
    if (st == PD_OK)
        st = pd_part_build_take(&mesh, &a->part, &part, &diag);
    if (st == PD_OK && !a->merge && cli_writer())
        plausible_warn(a, part);
    static_progress_stage("quasi-static and perturbed estimates");
    if (st == PD_OK)
        st = pd_static_estimate(part, &a->estimate, &res, &diag);
    static_progress_end();
    t_static = cli_wall_seconds() - t0;
    /* A signal before the drops (or, without drops, before the output)
     * ends the run here, nothing printed; one during the static estimate
     * stops it there (PD_ERR_CANCELLED). */
    if ((st == PD_OK || st == PD_ERR_CANCELLED) &&
        cli_any(st == PD_ERR_CANCELLED || signals_caught())) {
        code = cli_interrupt_code();
        goto done;
    }
    /* A shard prints its poses' own counts; its merge groups them. */
    if (st == PD_OK && a->group && !a->sim.nshards) {
        class_of = malloc(sizeof *class_of * (size_t)(res->nposes + 1));
        st = class_of ? pd_pose_classes(part, res, class_of, &nclasses, &diag) : PD_ERR_NOMEM;
        /* --effect resolves the effects the output shows, the classes'. */
        a->sim.effect_class_of = class_of;
        a->sim.effect_nclasses = nclasses;
    }
    if (st == PD_OK && a->dynamic && trace_out.f) {
        fprintf(trace_out.f, "t,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz,energy,depth,contacts,event\n");
        a->sim.trace = write_trace_row;
        a->sim.trace_user = trace_out.f;
    }
    if (st == PD_OK && a->dynamic) {
        st = cli_simulate(part, res, a, &sim, &diag);
        if (st == PD_OK && a->crosscheck && !sim->partial)
            st = crosscheck_run(part, res, a, xsim, &diag);
        t_sim = cli_wall_seconds() - t0 - t_static;
    }
    if (st == PD_OK && !cli_writer()) {
        code = 0;
        goto done;
    }
    if (st == PD_OK && class_of && sim)
        st = pd_sim_result_grouped(sim, class_of, nclasses, &gsim, &diag);
    for (int k = 0; k < VIZ_ENGINES && st == PD_OK && class_of; k++)
        if (xsim[k])
            st = pd_sim_result_grouped(xsim[k], class_of, nclasses, &xgsim[k], &diag);
    if (st == PD_OK && sim && a->crosscheck) {
        /* An engine an interruption kept from running leaves the run partial. */
        int partial = 0;
        for (int k = 0; k < VIZ_ENGINES; k++) {
            int mine = k == (int)a->sim.engine;
            const pd_sim_result *r = mine ? (gsim ? gsim : sim) : xgsim[k] ? xgsim[k] : xsim[k];
            xe_store.sim[k] = r;
            partial |= !r || r->partial;
        }
        xe = &xe_store;
        sim->partial |= partial;
        if (gsim)
            gsim->partial |= partial;
    }
    /* The report shows it when the drops' records were kept (not across
     * MPI ranks); --sensitivity needs them. */
    if (st == PD_OK && sim && pd_scene_ranged(&a->scene) &&
        (a->sensitivity || (a->pictures[VIZ_REPORT] && sim->trials)))
        st = pd_sim_sensitivity(sim, &a->scene, pd_contact_time_auto_size(part), class_of,
                                nclasses, &sens, &diag);
    static const char *const engine_labels[] = {"impulse", "ODE", "Bullet"};
    viz_input in = {a->path, part, res, gsim ? gsim : sim, class_of, nclasses,
                    engine_labels[a->sim.engine], sim ? &a->scene : NULL, measured, sens, xe};
    if (st == PD_OK && measured && (st = viz_check(&in, &diag)) != PD_OK) {
        code = fail_status(st, &diag, NULL);
        goto done;
    }
    if (st != PD_OK) {
        code = fail_status(st, &diag, a->path);
        goto done;
    }
    /* The side files before stdout: if one cannot be written in full (a
     * full disk, /dev/full), the run fails with nothing on stdout. None is
     * put in place before stdout is written in full too: a failed run
     * leaves every earlier file as it was. */
    int partial = sim && sim->partial;
    if (trials_out.f)
        write_trials(trials_out.f, sim, class_of, &a->scene, partial);
    if (transitions_out.f)
        write_transitions(transitions_out.f, gsim ? gsim : sim);
    if (sens_out.f) {
        write_sensitivity(sens_out.f, sens, partial);
        /* What the effects can tell apart, said whether or not it was
         * asked for: an effect inside it is no evidence of none. */
        if (sens->nparams > 0)
            fprintf(stderr, "%s: %s: these %ld drops resolve an effect to %.1f points (the "
                    "widest half of an effect's 95%% interval); four times the drops halve "
                    "it\n", prog, a->path, sens->n, 100 * sens->resolution);
    }
    if (!out_close(&trials_out) || !out_close(&trace_out) || !out_close(&transitions_out) ||
        !out_close(&sens_out)) {
        code = EXIT_INTERNAL;
        goto done;
    }
    viz_run run = {a->path, a->read.units, &a->estimate, &a->sim, t_static, t_sim,
                   cli_wall_seconds() - t0, a->argc, a->argv};
    for (int k = 0; k < VIZ_KINDS; k++) {
        if (!pic_out[k].f)
            continue;
        if ((st = viz_write_file((viz_kind)k, pic_out[k].f, &in, &run, &diag)) != PD_OK) {
            code = fail_status(st, &diag, NULL);
            goto done;
        }
        if (!out_close(&pic_out[k])) {
            code = EXIT_INTERNAL;
            goto done;
        }
    }
    if (a->verbose)
        print_summary(a, part, res);
    if (sim)
        print_sim_summary(a, sim);
    if (xe)
        print_crosscheck(a, xe, class_of ? nclasses : res->nposes, class_of != NULL);
    if (a->sim.nshards && !shard_write_identity(stdout, a, sim)) {
        code = EXIT_INTERNAL;
        goto done;
    }
    if (a->json)
        json_print(stdout, a, part, res, gsim ? gsim : sim, class_of, nclasses, xe,
                   cli_wall_seconds() - t0);
    else if (a->facets)
        print_facets(part, res);
    else if (class_of)
        print_classes(res, gsim, class_of, nclasses, xe);
    else
        print_poses(res, sim, xe);
    code = fflush(stdout) == 0 && !ferror(stdout) ? 0 : EXIT_INTERNAL;
    if (code) {
        fprintf(stderr, "%s: error writing the output: %s\n", prog, strerror(errno));
        goto done;
    }
    out_file *const outs[] = {&trials_out,  &trace_out,  &transitions_out, &sens_out,
                              &pic_out[0], &pic_out[1], &pic_out[2],      &pic_out[3]};
    _Static_assert(VIZ_KINDS == 4, "every picture is put in place");
    if (!out_place_all(outs, (int)(sizeof outs / sizeof outs[0])))
        code = EXIT_INTERNAL;
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
    out_abort(&trace_out);
    out_abort(&transitions_out);
    out_abort(&sens_out);
    pd_sensitivity_free(sens);
    for (int k = 0; k < VIZ_KINDS; k++)
        out_abort(&pic_out[k]);
    viz_measured_free(measured);
    free(class_of);
    pd_sim_result_free(gsim);
    pd_sim_result_free(sim);
    for (int k = 0; k < VIZ_ENGINES; k++) {
        pd_sim_result_free(xgsim[k]);
        pd_sim_result_free(xsim[k]);
    }
    pd_static_result_free(res);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return code;
}
