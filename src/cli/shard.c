/* shard.c: --shard K/N, and the shards posedrop merge (merge.c) sums.
 *
 * A shard prints two leading '#' lines before its CSV: the run's identity
 *   # posedrop VERSION shard=K/N part=PATH sha256=HEX units=... group=0|1
 * (every setting that changes a result, numbers as %.17g so they read back
 * to the same double), then its totals that no column holds
 *   # totals collisions=C energy_gain=G fallbacks=F
 * and the per-pose CSV with, for --initial stationary, the chain's counts
 * (first, to_1 .. to_k). merge checks that the shards are the N shards of
 * one run, reads the part again (its SHA-256 must not have changed), sums
 * the counts and prints through cli_run what the unsharded run prints. */
#include <errno.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include "base/file_read.h"
#include "cli/cli.h"
#include "cli/shard_read.h"

/* The largest shard count: far beyond a cluster's job array limits (Slurm's
 * MaxArraySize defaults to 1001), so a larger N is a typo. */
#define SHARDS_MAX 100000L

int shard_parse(const char *text, pd_sim_options *sim)
{
    char *end;
    errno = 0;
    long k = strtol(text, &end, 10);
    if (end == text || *end != '/' || errno)
        return 0;
    const char *rest = end + 1;
    long n = strtol(rest, &end, 10);
    if (end == rest || *end != '\0' || errno || n < 1 || n > SHARDS_MAX || k < 1 || k > n)
        return 0;
    sim->nshards = (int)n;
    sim->shard = (int)(k - 1);
    return 1;
}

/* Names of the enumerations, in enum order. */
static const char *const units_names[] = {"m", "cm", "mm", "in", NULL};
static const char *const format_names[] = {"auto", "off", "stl", "obj", NULL};
static const char *const topple_names[] = {"descent", "edge", NULL};
static const char *const compare_names[] = {"raw", "qs", NULL};
static const char *const band_names[] = {"rect", "exact", NULL};
static const char *const engine_names[] = {"impulse", "ode", "bullet", NULL};
static const char *const law_names[] = {"poisson", "energetic", NULL};
static const char *const initial_names[] = {"uniform", "bootstrap", "stationary", NULL};
static const char *const dist_names[] = {"fixed", "uniform", "log", NULL};

/* The identity as key=value words, in a fixed order: write_identity prints
 * it, and merge rebuilds the options from it and prints it again to prove
 * that nothing was lost on the way. */
typedef struct {
    char text[4096];
    size_t len;
} words;

static void word(words *w, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

static void word(words *w, const char *key, const char *fmt, ...)
{
    if (w->len < sizeof w->text)
        w->len += (size_t)snprintf(w->text + w->len, sizeof w->text - w->len, " %s=", key);
    va_list ap;
    va_start(ap, fmt);
    if (w->len < sizeof w->text)
        w->len += (size_t)vsnprintf(w->text + w->len, sizeof w->text - w->len, fmt, ap);
    va_end(ap);
}

/* Paths may hold spaces: bytes outside '!'..'~', and '%' and '=', are
 * written %XX. */
static void escaped(words *w, const char *key, const char *s)
{
    char buf[3 * 1024 + 1];
    size_t n = 0;
    for (; *s && n + 4 < sizeof buf; s++) {
        unsigned char c = (unsigned char)*s;
        if (c <= ' ' || c > '~' || c == '%' || c == '=')
            n += (size_t)snprintf(buf + n, sizeof buf - n, "%%%02X", c);
        else
            buf[n++] = (char)c;
    }
    buf[n] = '\0';
    word(w, key, "%s", buf);
}

static void identity_words(const cli_args *a, const char *sha, words *w)
{
    w->len = 0;
    w->text[0] = '\0';
    escaped(w, "part", a->path);
    word(w, "sha256", "%s", sha);
    word(w, "units", "%s", units_names[a->read.units]);
    word(w, "format", "%s", format_names[a->read.format]);
    if (a->part.com_given)
        word(w, "com", "%.17g,%.17g,%.17g", a->part.com.x, a->part.com.y, a->part.com.z);
    else
        word(w, "com", "mesh");
    word(w, "topple", "%s", topple_names[a->estimate.topple]);
    word(w, "epsilon_rad", "%.17g", a->estimate.epsilon);
    word(w, "pqs_compare", "%s", compare_names[a->estimate.compare]);
    word(w, "pqs_band", "%s", band_names[a->estimate.band]);
    word(w, "engine", "%s", engine_names[a->sim.engine]);
    word(w, "dt", "%.17g", a->sim.dt);
    word(w, "time_limit", "%.17g", a->sim.time_limit);
    word(w, "n", "%ld", a->sim.ndrops);
    word(w, "seed", "%" PRIu64, a->sim.seed);
    const pd_scene *s = &a->scene;
    word(w, "height", "%.17g", s->height);
    word(w, "belt_speed", "%.17g", s->belt_speed);
    word(w, "mu", "%.17g", s->mu);
    word(w, "restitution", "%.17g", s->restitution);
    word(w, "restitution_law", "%s", law_names[s->law]);
    word(w, "vibration_rad", "%.17g", s->vibration);
    word(w, "initial", "%s", initial_names[s->initial]);
    word(w, "gravity", "%.17g", s->gravity);
    word(w, "contact_time", "%.17g", s->contact_time);
    /* What a run without them never had is written only when set, so that
     * such a run's identity is what it always was. */
    if (s->tumble != 0.0)
        word(w, "tumble", "%.17g", s->tumble);
    for (int k = 0; k < PD_NPARAMS; k++) {
        const pd_dist *d = &s->range[k];
        if (d->kind == PD_DIST_FIXED)
            continue;
        char key[48];
        snprintf(key, sizeof key, "%s_range", pd_scene_param_name((pd_scene_param)k));
        word(w, key, "%s:%.17g:%.17g%s", dist_names[d->kind], d->lo, d->hi,
             d->auto_multiple ? ":auto" : "");
    }
    word(w, "group", "%d", a->group);
}

int shard_write_identity(FILE *out, const cli_args *a, const pd_sim_result *sim)
{
    char sha[65];
    if (!sha256_file(a->path, sha)) {
        fprintf(stderr, "%s: %s: cannot read: %s\n", prog, a->path, strerror(errno));
        return 0;
    }
    words w;
    identity_words(a, sha, &w);
    if (w.len >= sizeof w.text) {
        fprintf(stderr, "%s: %s: the path is too long to name in a shard\n", prog, a->path);
        return 0;
    }
    fprintf(out, "# posedrop %s shard=%d/%d%s\n", pd_version(), a->sim.shard + 1,
            a->sim.nshards, w.text);
    fprintf(out, "# totals collisions=%ld energy_gain=%ld fallbacks=%ld\n", sim->collisions,
            sim->energy_gain, sim->fallbacks);
    return 1;
}

/* ---- merge ---- */

static shard_file *shards;
static int nshard_files;

static void free_shards(void)
{
    for (int i = 0; i < nshard_files; i++)
        shard_file_clear(&shards[i]);
    free(shards);
    shards = NULL;
    nshard_files = 0;
}

/* The first word where this shard's identity (x) differs from the first
 * shard's (y), for the message. */
static void first_difference(const char *x, const char *y, const char *yfile, char *out,
                             size_t size)
{
    while (*x == ' ' && *y == ' ') {
        size_t lx = strcspn(x + 1, " "), ly = strcspn(y + 1, " ");
        if (lx != ly || strncmp(x + 1, y + 1, lx) != 0) {
            snprintf(out, size, "it has '%.*s', %s '%.*s'", (int)lx, x + 1, yfile, (int)ly, y + 1);
            return;
        }
        x += 1 + lx;
        y += 1 + ly;
    }
    snprintf(out, size, "their settings differ");
}

/* The N shards of one run, each once, none partial. */
static int check_shards(void)
{
    const shard_file *s0 = &shards[0];
    char msg[1024], diff[600];
    for (int i = 1; i < nshard_files; i++) {
        const shard_file *s = &shards[i];
        if (strcmp(s->version, s0->version) != 0)
            snprintf(msg, sizeof msg, "another posedrop version than %s: it is from posedrop %s, "
                     "%s from %s", s0->file, s->version, s0->file, s0->version);
        else if (s->n != s0->n)
            snprintf(msg, sizeof msg, "another shard count than %s: it is shard %d/%d, %s shard "
                     "%d/%d", s0->file, s->k, s->n, s0->file, s0->k, s0->n);
        else if (strcmp(s->identity, s0->identity) != 0) {
            first_difference(s->identity, s0->identity, s0->file, diff, sizeof diff);
            snprintf(msg, sizeof msg, "not a shard of the same run as %s: %s", s0->file, diff);
        } else
            msg[0] = '\0';
        if (msg[0])
            return shard_fail(s->file, 0, msg);
        for (int j = 0; j < i; j++)
            if (shards[j].k == s->k) {
                snprintf(msg, sizeof msg, "shard %d/%d again (already in %s)", s->k, s->n,
                         shards[j].file);
                return shard_fail(s->file, 0, msg);
            }
    }
    if (nshard_files != s0->n) {
        for (int k = 1; k <= s0->n; k++) {
            int found = 0;
            for (int i = 0; i < nshard_files; i++)
                found |= shards[i].k == k;
            if (!found) {
                fprintf(stderr, "%s: shard %d/%d is missing: the run has %d shards, %d given\n",
                        prog, k, s0->n, s0->n, nshard_files);
                return 0;
            }
        }
    }
    return 1;
}

static int pick(const char *value, const char *const *names, int *out)
{
    for (int i = 0; names[i]; i++)
        if (strcmp(value, names[i]) == 0) {
            *out = i;
            return 1;
        }
    return 0;
}

static int unescape(const char *in, char *out, size_t size)
{
    size_t n = 0;
    for (; *in; in++) {
        unsigned v;
        if (n + 1 >= size)
            return 0;
        if (*in == '%') {
            if (sscanf(in + 1, "%2x", &v) != 1 || !in[1] || !in[2])
                return 0;
            out[n++] = (char)v;
            in += 2;
        } else {
            out[n++] = *in;
        }
    }
    out[n] = '\0';
    return 1;
}

static int read_double(const char *text, double *out)
{
    char *end;
    *out = strtod(text, &end);
    return end != text && *end == '\0';
}

/* The words identity_words writes only when set: tumble and the ranges. */
static int ranges_from_identity(const char *id, pd_scene *s)
{
    char v[1100];
    if (shard_find_word(id, "tumble", v, sizeof v) && !read_double(v, &s->tumble))
        return 0;
    for (int k = 0; k < PD_NPARAMS; k++) {
        char key[48];
        snprintf(key, sizeof key, "%s_range", pd_scene_param_name((pd_scene_param)k));
        if (!shard_find_word(id, key, v, sizeof v))
            continue;
        pd_dist *d = &s->range[k];
        char kind[16], *end;
        const char *p = v + strcspn(v, ":");
        if (*p != ':' || (size_t)(p - v) >= sizeof kind)
            return 0;
        memcpy(kind, v, (size_t)(p - v));
        kind[p - v] = '\0';
        int e;
        if (!pick(kind, dist_names, &e) || e == PD_DIST_FIXED)
            return 0;
        d->kind = (pd_dist_kind)e;
        d->lo = strtod(p + 1, &end);
        if (*end != ':')
            return 0;
        d->hi = strtod(end + 1, &end);
        d->auto_multiple = strcmp(end, ":auto") == 0;
        if (*end && !d->auto_multiple)
            return 0;
    }
    return 1;
}

/* The options of the run the shards came from, from their identity. */
static int options_from_identity(const shard_file *s, cli_args *a, char *path, size_t path_size,
                                 char sha[65])
{
    const char *id = s->identity;
    char v[1100];
    int e[10], ok = 1;
    uint64_t seed = 0;
    double *doubles[] = {&a->estimate.epsilon, &a->sim.dt, &a->scene.height, &a->scene.belt_speed,
                         &a->scene.mu, &a->scene.restitution, &a->scene.vibration,
                         &a->scene.gravity, &a->scene.contact_time};
    static const char *const dkeys[] = {"epsilon_rad", "dt", "height", "belt_speed", "mu",
                                        "restitution", "vibration_rad", "gravity", "contact_time"};
    for (int i = 0; ok && i < 9; i++)
        ok = shard_find_word(id, dkeys[i], v, sizeof v) && read_double(v, doubles[i]);
    ok = ok && shard_find_word(id, "part", v, sizeof v) && unescape(v, path, path_size) &&
         shard_find_word(id, "sha256", v, sizeof v) && strlen(v) == 64 && strcpy(sha, v) &&
         shard_find_word(id, "units", v, sizeof v) && pick(v, units_names, &e[0]) &&
         shard_find_word(id, "format", v, sizeof v) && pick(v, format_names, &e[1]) &&
         shard_find_word(id, "topple", v, sizeof v) && pick(v, topple_names, &e[2]) &&
         shard_find_word(id, "pqs_compare", v, sizeof v) && pick(v, compare_names, &e[3]) &&
         shard_find_word(id, "pqs_band", v, sizeof v) && pick(v, band_names, &e[4]) &&
         shard_find_word(id, "engine", v, sizeof v) && pick(v, engine_names, &e[5]) &&
         shard_find_word(id, "restitution_law", v, sizeof v) && pick(v, law_names, &e[6]) &&
         shard_find_word(id, "initial", v, sizeof v) && pick(v, initial_names, &e[7]) &&
         shard_find_word(id, "group", v, sizeof v) && sscanf(v, "%d", &e[8]) == 1 &&
         shard_find_word(id, "n", v, sizeof v) && sscanf(v, "%ld", &a->sim.ndrops) == 1 &&
         shard_find_word(id, "seed", v, sizeof v) && sscanf(v, "%" SCNu64, &seed) == 1 &&
         shard_find_word(id, "com", v, sizeof v);
    if (ok && strcmp(v, "mesh") != 0) {
        a->part.com_given = 1;
        ok = sscanf(v, "%lf,%lf,%lf", &a->part.com.x, &a->part.com.y, &a->part.com.z) == 3;
    }
    ok = ok && ranges_from_identity(id, &a->scene);
    if (!ok)
        return shard_fail(s->file, 1, "the run's settings are incomplete or unreadable");
    a->read.units = (pd_units)e[0];
    a->read.format = (pd_mesh_format)e[1];
    a->estimate.topple = (pd_topple_rule)e[2];
    a->estimate.compare = (pd_pqs_compare)e[3];
    a->estimate.band = (pd_pqs_band)e[4];
    a->sim.engine = (pd_engine_kind)e[5];
    a->scene.law = (pd_restitution_law)e[6];
    a->scene.initial = (pd_initial)e[7];
    a->group = e[8] != 0;
    a->sim.seed = seed;
    a->path = path;
    /* Every word read back must print as it was written. */
    words w;
    identity_words(a, sha, &w);
    if (strcmp(w.text, id) != 0)
        return shard_fail(s->file, 1, "the run's settings do not read back as written (a shard "
                          "of another posedrop version, or edited)");
    return 1;
}

pd_status merge_shards(const pd_static_result *res, cli_args *a, pd_sim_result **sum,
                       pd_diag *diag)
{
    pd_sim_options o = a->sim;
    o.nshards = 0;
    pd_status st = pd_sim_result_new(res, &a->scene, &o, sum, diag);
    for (int i = 0; st == PD_OK && i < nshard_files; i++) {
        const shard_file *f = &shards[i];
        if (f->nposes != res->nposes || !f->to != !(*sum)->transitions) {
            snprintf(diag->message, sizeof diag->message, "%s: %d poses%s, but the part has %d%s",
                     f->file, f->nposes, f->to ? " with the chain's counts" : "", res->nposes,
                     (*sum)->transitions ? " and the run is stationary" : "");
            st = PD_ERR_FORMAT;
            break;
        }
        long want = pd_shard_drops(a->sim.ndrops, f->k - 1, f->n);
        if (f->drops != want) {
            snprintf(diag->message, sizeof diag->message, "%s: %ld drops, but shard %d/%d of a "
                     "run of %ld drops has %ld", f->file, f->drops, f->k, f->n, a->sim.ndrops, want);
            st = PD_ERR_FORMAT;
            break;
        }
        pd_sim_result s = **sum;
        s.n = f->drops;
        s.unsettled = f->unsettled;
        s.collisions = f->collisions;
        s.energy_gain = f->energy_gain;
        s.fallbacks = f->fallbacks;
        s.partial = f->partial;
        s.count = f->count;
        s.first_count = f->first;
        s.transitions = f->to;
        s.nshards = f->n;
        s.shard = f->k - 1;
        s.added = NULL;
        s.added_nshards = 0;
        st = pd_sim_result_add(*sum, &s, diag);
    }
    if (st == PD_OK)
        st = pd_sim_result_finish(*sum, diag);
    if (st != PD_OK) {
        pd_sim_result_free(*sum);
        *sum = NULL;
    }
    return st;
}

int shard_load(char **files, int nfiles, cli_args *a, char *path, size_t path_size, char sha[65])
{
    nshard_files = nfiles;
    shards = calloc((size_t)nshard_files, sizeof *shards);
    if (!shards) {
        fprintf(stderr, "%s: out of memory\n", prog);
        return 0;
    }
    int ok = 1;
    for (int i = 0; ok && i < nshard_files; i++)
        ok = shard_read(files[i], &shards[i]);
    return ok && check_shards() && options_from_identity(&shards[0], a, path, path_size, sha);
}

void shard_unload(void)
{
    free_shards();
}
