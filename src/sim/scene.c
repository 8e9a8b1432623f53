/* scene.c: the settings of a drop, their defaults (the paper's section 5.2)
 * and their text form, shared by scene files and the command line. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "base/fail.h"
#include "base/file_read.h"
#include "base/number.h"
#include "base/rng.h"
#include "posedrop/sim.h"
#include "sim/scene.h"
#include "sim/sim_tol.h"

void pd_scene_default(pd_scene *s)
{
    if (!s)
        return;
    s->height = 0.12;
    s->belt_speed = 0.05;
    s->mu = 0.3;
    s->restitution = 0.3;
    s->law = PD_RESTITUTION_POISSON;
    s->vibration = 1.5 * M_PI / 180.0;
    s->initial = PD_INITIAL_UNIFORM;
    s->gravity = 9.81;
    s->contact_time = PD_CONTACT_TIME_AUTO;
    s->tumble = 0.0;
    memset(s->range, 0, sizeof s->range); /* PD_DIST_FIXED */
}

/* The Hertz estimate for the paper's scene (docs/contact.md) and the part
 * it was made for, a 1 cm cube: its diagonal and volume. */
#define CONTACT_T_REF 5e-4
#define CONTACT_SIZE_REF (0.01 * 1.7320508075688772935)
#define CONTACT_VOLUME_REF 1e-6
#define CONTACT_G_REF 9.81

/* The longest automatic duration for a part of size L (below). */
static double contact_t_sink(double size)
{
    return M_PI * sqrt(PD_CONTACT_AUTO_SINK_REL * size / CONTACT_G_REF);
}

double pd_contact_time_auto(double size)
{
    /* No longer than a contact that the part's weight, under the estimate's
     * gravity, presses PD_CONTACT_AUTO_SINK_REL of its size into the floor:
     * a contact of duration T is a spring of angular frequency pi / T,
     * which sinks g (T / pi)^2 under the weight. */
    return fmin(CONTACT_T_REF * size / CONTACT_SIZE_REF, contact_t_sink(size));
}

double pd_contact_time_auto_part(const pd_part *part)
{
    if (!part || !part->hull)
        return 0.0;
    /* A needle's mass is far below L^3: by its length alone a 1 m needle
     * 1 mm thick got a 29 ms contact, whose static compression (about
     * g T^2 / 13) sank it deeper than its thickness and kept every drop
     * from settling. Powers taken apart so that no product of lengths
     * leaves the doubles over the supported sizes. */
    double volume = part->mass_known ? part->mass.volume : part->hull->volume;
    double t = CONTACT_T_REF * pow(volume / CONTACT_VOLUME_REF, 0.4) *
               pow(CONTACT_SIZE_REF / part->size, 0.2);
    return fmin(t, contact_t_sink(part->size));
}

double pd_contact_time_auto_size(const pd_part *part)
{
    /* pd_contact_time_auto rises with the size, linear up to its cap, then
     * as the cap: the length on whichever branch gives this duration. */
    double t = pd_contact_time_auto_part(part), k = CONTACT_T_REF / CONTACT_SIZE_REF;
    double cross = M_PI * M_PI * PD_CONTACT_AUTO_SINK_REL / (CONTACT_G_REF * k * k);
    double linear = t / k;
    return linear <= cross ? linear
                           : CONTACT_G_REF * (t / M_PI) * (t / M_PI) / PD_CONTACT_AUTO_SINK_REL;
}

typedef struct {
    const char *key;
    size_t field;  /* offsetof the double in pd_scene */
    double scale;  /* text value times scale is stored (degrees -> rad) */
    pd_num_rule rule;
    int param;     /* its pd_scene_param, -1 for one that takes no range */
} numeric_key;

/* Ranges: a drop needs a non-negative height and positive gravity; friction
 * beyond 10 is no longer a material (the tests go to 10); restitution above 1
 * would create energy; vibration is a tilt; a tumble of 10^4 rad/s turns a
 * 1 cm part's corner at 50 m/s. The same table checks the text
 * (pd_scene_set) and a scene filled in by a program (pd_scene_check), values
 * and ranges alike. */
#define REAL(what, lo, hi) {what, 0, lo, hi, 0, 0, 0, 0}
static const numeric_key keys[] = {
    {"height", offsetof(pd_scene, height), 1.0, REAL("a drop height in m", 0.0, 1e3),
     PD_PARAM_HEIGHT},
    {"belt_speed", offsetof(pd_scene, belt_speed), 1.0, REAL("a belt speed in m/s", -1e3, 1e3),
     PD_PARAM_BELT_SPEED},
    {"mu", offsetof(pd_scene, mu), 1.0, REAL("a friction coefficient", 0.0, 10.0), PD_PARAM_MU},
    {"restitution", offsetof(pd_scene, restitution), 1.0, REAL("a restitution", 0.0, 1.0),
     PD_PARAM_RESTITUTION},
    {"vibration", offsetof(pd_scene, vibration), M_PI / 180.0,
     REAL("an angle in degrees", 0.0, 180.0), PD_PARAM_VIBRATION},
    {"gravity", offsetof(pd_scene, gravity), 1.0, REAL("an acceleration in m/s^2", 1e-3, 1e3), -1},
    {"contact_time", offsetof(pd_scene, contact_time), 1.0, REAL("a duration in s", 0.0, 1.0),
     PD_PARAM_CONTACT_TIME},
    {"tumble", offsetof(pd_scene, tumble), 1.0, REAL("an angular speed in rad/s", 0.0, 1e4),
     PD_PARAM_TUMBLE},
};
enum { NNUMERIC = sizeof keys / sizeof keys[0] };

/* A contact_time range in multiples of auto ("0.3x:3x"): a thousandth to a
 * thousand times the Hertz estimate covers every material pair from steel on
 * steel to foam. */
static const pd_num_rule multiple_rule = REAL("a multiple of auto", 1e-3, 1e3);

/* Every key a scene accepts, for messages and duplicate checks. */
static const char *const scene_keys[] = {"height", "belt_speed", "mu", "restitution",
                                         "restitution_law", "vibration", "initial", "gravity",
                                         "contact_time", "tumble"};
enum { NKEYS = sizeof scene_keys / sizeof scene_keys[0] };

static int key_index(const char *key)
{
    for (int i = 0; i < NKEYS; i++)
        if (strcmp(key, scene_keys[i]) == 0)
            return i;
    return -1;
}

static double *field(pd_scene *s, const numeric_key *k)
{
    return (double *)(void *)((char *)s + k->field);
}

/* The key of a pd_scene_param; NULL for any other number (gravity's -1,
 * which marks a key that takes no range, included). */
static const numeric_key *param_key(int param)
{
    if (param < 0 || param >= PD_NPARAMS)
        return NULL;
    for (int i = 0; i < NNUMERIC; i++)
        if (keys[i].param == param)
            return &keys[i];
    return NULL;
}

const char *pd_scene_param_name(pd_scene_param param)
{
    const numeric_key *k = param_key((int)param);
    return k ? k->key : NULL;
}

/* Checks one stored number v against rule scaled by scale; PD_NUM_OK or why
 * not. Rounding is monotonic, so lo * scale and hi * scale bound exactly
 * what the text's rule accepts; a subnormal is refused as the text reader
 * refuses "1e-320". */
static int check_number(const pd_num_rule *rule, double scale, double v)
{
    if (!isfinite(v))
        return PD_NUM_NONFINITE;
    if (v != 0.0 && fabs(v) < DBL_MIN)
        return PD_NUM_TINY;
    if (v < rule->lo * scale || v > rule->hi * scale)
        return PD_NUM_RANGE;
    return PD_NUM_OK;
}

/* The failure for v refused by rule (outcome), in the text's unit. */
static pd_status number_fail(pd_diag *diag, const char *key, const char *what,
                             const pd_num_rule *rule, double scale, double v, int outcome)
{
    char text[32], msg[PD_DIAG_MESSAGE_LEN];
    snprintf(text, sizeof text, "%.17g", v / scale);
    pd_num_message(msg, sizeof msg, rule, text, outcome);
    return pd_fail(diag, outcome == PD_NUM_NONFINITE ? PD_ERR_NONFINITE : PD_ERR_RANGE,
                   "scene %s%s: %s", key, what, msg);
}

static pd_status check_range(const numeric_key *k, const pd_dist *d, pd_diag *diag)
{
    if ((unsigned)d->kind > (unsigned)PD_DIST_LOG_UNIFORM)
        return pd_fail(diag, PD_ERR_RANGE, "scene %s: range kind %d: expected PD_DIST_FIXED, "
                       "PD_DIST_UNIFORM or PD_DIST_LOG_UNIFORM", k->key, (int)d->kind);
    if (d->auto_multiple != 0 && (d->auto_multiple != 1 || k->param != PD_PARAM_CONTACT_TIME))
        return pd_fail(diag, PD_ERR_RANGE, "scene %s: auto_multiple is %d: expected 0%s", k->key,
                       d->auto_multiple, k->param == PD_PARAM_CONTACT_TIME ? " or 1" : " (only "
                       "contact_time takes multiples of auto)");
    if (d->kind == PD_DIST_FIXED)
        return PD_OK;
    const pd_num_rule *rule = d->auto_multiple ? &multiple_rule : &k->rule;
    double scale = d->auto_multiple ? 1.0 : k->scale;
    int rc = check_number(rule, scale, d->lo);
    if (rc != PD_NUM_OK)
        return number_fail(diag, k->key, " range's low end", rule, scale, d->lo, rc);
    if ((rc = check_number(rule, scale, d->hi)) != PD_NUM_OK)
        return number_fail(diag, k->key, " range's high end", rule, scale, d->hi, rc);
    if (d->lo > d->hi)
        return pd_fail(diag, PD_ERR_RANGE, "scene %s: range %g:%g: the low end is above the "
                       "high end", k->key, d->lo / scale, d->hi / scale);
    if (d->kind == PD_DIST_LOG_UNIFORM && !(d->lo > 0.0))
        return pd_fail(diag, PD_ERR_RANGE, "scene %s: a log-uniform range needs a low end above "
                       "0, got %g", k->key, d->lo / scale);
    return PD_OK;
}

pd_status pd_scene_check(const pd_scene *scene, pd_diag *diag)
{
    if (!scene)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_check: NULL scene");
    for (int i = 0; i < NNUMERIC; i++) {
        const numeric_key *k = &keys[i];
        double v = *field((pd_scene *)scene, k);
        int rc = k->field == offsetof(pd_scene, contact_time) && v == PD_CONTACT_TIME_AUTO
                     ? PD_NUM_OK
                     : check_number(&k->rule, k->scale, v);
        if (rc != PD_NUM_OK)
            return number_fail(diag, k->key, "", &k->rule, k->scale, v, rc);
        pd_status st = k->param >= 0 ? check_range(k, &scene->range[k->param], diag) : PD_OK;
        if (st != PD_OK)
            return st;
    }
    if ((unsigned)scene->law > (unsigned)PD_RESTITUTION_ENERGETIC)
        return pd_fail(diag, PD_ERR_RANGE, "scene restitution_law is %d: expected "
                       "PD_RESTITUTION_POISSON or PD_RESTITUTION_ENERGETIC", (int)scene->law);
    if ((unsigned)scene->initial > (unsigned)PD_INITIAL_STATIONARY)
        return pd_fail(diag, PD_ERR_RANGE, "scene initial is %d: expected PD_INITIAL_UNIFORM, "
                       "PD_INITIAL_BOOTSTRAP or PD_INITIAL_STATIONARY", (int)scene->initial);
    return PD_OK;
}

const char *pd_scene_format(const pd_scene *scene, pd_scene_param param, char *buf, size_t size)
{
    const numeric_key *k = param_key((int)param);
    if (!buf || size == 0)
        return buf;
    if (!scene || !k) {
        buf[0] = '\0';
        return buf;
    }
    const pd_dist *d = &scene->range[param];
    double v = *field((pd_scene *)scene, k);
    if (d->kind == PD_DIST_FIXED && param == PD_PARAM_CONTACT_TIME && v == PD_CONTACT_TIME_AUTO)
        snprintf(buf, size, "auto");
    else {
        /* Each number the shortest that reads back to the same scene. */
        char a[32], b[32];
        double scale = d->auto_multiple ? 1.0 : k->scale;
        if (d->kind == PD_DIST_FIXED)
            snprintf(buf, size, "%s", pd_num_format(a, sizeof a, v, k->scale));
        else if (d->auto_multiple && d->lo == d->hi)
            snprintf(buf, size, "%sx", pd_num_format(a, sizeof a, d->lo, scale));
        else if (d->auto_multiple)
            snprintf(buf, size, "%sx:%sx%s", pd_num_format(a, sizeof a, d->lo, scale),
                     pd_num_format(b, sizeof b, d->hi, scale),
                     d->kind == PD_DIST_LOG_UNIFORM ? " log" : " uniform");
        else
            snprintf(buf, size, "%s:%s%s", pd_num_format(a, sizeof a, d->lo, scale),
                     pd_num_format(b, sizeof b, d->hi, scale),
                     d->kind == PD_DIST_LOG_UNIFORM ? " log" : "");
    }
    return buf;
}

int pd_scene_varies(const pd_scene *scene, pd_scene_param param)
{
    if (!scene || (unsigned)param >= PD_NPARAMS)
        return 0;
    const pd_dist *d = &scene->range[param];
    return d->kind != PD_DIST_FIXED && d->lo < d->hi;
}

int pd_scene_ranged(const pd_scene *scene)
{
    for (int i = 0; i < PD_NPARAMS; i++)
        if (pd_scene_varies(scene, (pd_scene_param)i))
            return 1;
    return 0;
}

/* The parameters' stream of drop `drop`: the orientation stream's
 * construction with the seed salted, so that it is apart from every drop's
 * orientation stream of the same run. Its first PD_NPARAMS uniforms are the
 * parameters' (in pd_scene_param order, drawn whether or not a parameter is
 * ranged, so each one's draw depends on its own index only), then the
 * tumble's axis. */
static void param_stream(pd_rng *r, uint64_t seed, long drop)
{
    pd_rng_init(r, seed ^ 0x5ca1ab1e0ddba11ULL, (uint64_t)drop);
}

static double draw_one(const pd_dist *d, double u)
{
    if (d->lo == d->hi)
        return d->lo;
    double v = d->kind == PD_DIST_LOG_UNIFORM ? exp(log(d->lo) + u * (log(d->hi) - log(d->lo)))
                                              : d->lo + u * (d->hi - d->lo);
    return fmin(fmax(v, d->lo), d->hi);
}

void pd_scene_draw(const pd_scene *scene, double part_size, uint64_t seed, long drop,
                   double values[PD_NPARAMS], pd_scene *drawn)
{
    if (!scene || !values)
        return;
    pd_rng r;
    param_stream(&r, seed, drop);
    double u[PD_NPARAMS];
    for (int i = 0; i < PD_NPARAMS; i++)
        u[i] = pd_rng_uniform(&r);
    if (drawn)
        *drawn = *scene;
    for (int i = 0; i < PD_NPARAMS; i++) {
        const numeric_key *k = param_key(i);
        const pd_dist *d = &scene->range[i];
        double v = *field((pd_scene *)scene, k);
        if (d->kind != PD_DIST_FIXED) {
            v = draw_one(d, u[i]);
            if (d->auto_multiple)
                v *= pd_contact_time_auto(part_size);
            if (drawn) {
                *field(drawn, k) = v;
                drawn->range[i].kind = PD_DIST_FIXED;
            }
        } else if (i == PD_PARAM_CONTACT_TIME && v == PD_CONTACT_TIME_AUTO) {
            v = pd_contact_time_auto(part_size);
        }
        values[i] = v;
    }
}

void pd_scene_tumble_axis(uint64_t seed, long drop, double axis[3])
{
    pd_rng r;
    param_stream(&r, seed, drop);
    for (int i = 0; i < PD_NPARAMS; i++)
        (void)pd_rng_uniform(&r);
    pd_vec3 a = pd_rng_unit_vector(&r);
    axis[0] = a.x;
    axis[1] = a.y;
    axis[2] = a.z;
}

double pd_scene_quantile(const pd_scene *scene, pd_scene_param param, double part_size, double v)
{
    if (!scene || (unsigned)param >= PD_NPARAMS)
        return 0.5;
    const pd_dist *d = &scene->range[param];
    if (d->kind == PD_DIST_FIXED || !(d->lo < d->hi))
        return 0.5;
    if (d->auto_multiple)
        v /= pd_contact_time_auto(part_size);
    double q = d->kind == PD_DIST_LOG_UNIFORM
                   ? (log(v) - log(d->lo)) / (log(d->hi) - log(d->lo))
                   : (v - d->lo) / (d->hi - d->lo);
    return isfinite(q) ? fmin(fmax(q, 0.0), 1.0) : 0.5;
}

/* Copies the trimmed text [a, b) into buf (NUL-terminated); 0 if too long. */
static int token(const char *a, const char *b, char *buf, size_t size)
{
    while (a < b && (*a == ' ' || *a == '\t'))
        a++;
    while (b > a && (b[-1] == ' ' || b[-1] == '\t'))
        b--;
    if ((size_t)(b - a) >= size)
        return 0;
    memcpy(buf, a, (size_t)(b - a));
    buf[b - a] = '\0';
    return 1;
}

/* One number of a value with its message on failure. */
static pd_status read_number(const char *key, const pd_num_rule *rule, const char *text,
                             double *v, pd_diag *diag)
{
    int rc = pd_num_read(rule, text, v, NULL);
    if (rc == PD_NUM_OK)
        return PD_OK;
    char msg[PD_DIAG_MESSAGE_LEN];
    pd_num_message(msg, sizeof msg, rule, text, rc);
    return pd_fail(diag, rc == PD_NUM_BAD || rc == PD_NUM_NONFINITE ? PD_ERR_PARSE : PD_ERR_RANGE,
                   "%s: %s", key, msg);
}

/* "LO:HI [uniform|log]" into *d; contact_time's ends may be "0.3x". */
static pd_status parse_range(const numeric_key *k, const char *value, pd_dist *d, pd_diag *diag)
{
    const char *colon = strchr(value, ':');
    const char *end = value + strlen(value);
    char lo[128], hi[128], kind[32] = "";
    /* The kind word, if any, follows the high end after a blank or a second
     * colon (a command line's one word: 1e-4:1e-3:log). */
    const char *rest = colon + 1;
    while (*rest == ' ' || *rest == '\t')
        rest++;
    const char *hi_end = rest + strcspn(rest, " \t:");
    const char *kind_at = *hi_end == ':' ? hi_end + 1 : hi_end;
    if (!token(value, colon, lo, sizeof lo) || !token(rest, hi_end, hi, sizeof hi) ||
        !token(kind_at, end, kind, sizeof kind))
        return pd_fail(diag, PD_ERR_PARSE, "%s: a range is too long: '%.40s'", k->key, value);
    memset(d, 0, sizeof *d);
    d->kind = k->param == PD_PARAM_CONTACT_TIME ? PD_DIST_LOG_UNIFORM : PD_DIST_UNIFORM;
    if (strcmp(kind, "log") == 0)
        d->kind = PD_DIST_LOG_UNIFORM;
    else if (strcmp(kind, "uniform") == 0)
        d->kind = PD_DIST_UNIFORM;
    else if (*kind)
        return pd_fail(diag, PD_ERR_PARSE, "%s: expected a range LO:HI, optionally followed by "
                       "uniform or log, got '%.40s'", k->key, value);
    size_t nlo = strlen(lo), nhi = strlen(hi);
    int xlo = nlo > 0 && lo[nlo - 1] == 'x', xhi = nhi > 0 && hi[nhi - 1] == 'x';
    if (xlo || xhi) {
        if (k->param != PD_PARAM_CONTACT_TIME || !xlo || !xhi)
            return pd_fail(diag, PD_ERR_PARSE, "%s: %s, got '%.40s'", k->key,
                           k->param == PD_PARAM_CONTACT_TIME
                               ? "a range in multiples of auto has both ends so, as 0.3x:3x"
                               : "only contact_time takes multiples of auto (0.3x:3x)", value);
        lo[nlo - 1] = hi[nhi - 1] = '\0';
        d->auto_multiple = 1;
    }
    const pd_num_rule *rule = d->auto_multiple ? &multiple_rule : &k->rule;
    pd_status st = read_number(k->key, rule, lo, &d->lo, diag);
    if (st == PD_OK)
        st = read_number(k->key, rule, hi, &d->hi, diag);
    if (st != PD_OK)
        return st;
    if (!d->auto_multiple) {
        d->lo *= k->scale;
        d->hi *= k->scale;
    }
    return PD_OK;
}

/* Whether value is one multiple of auto, "3x" (blanks around allowed). */
static int multiple_alone(const char *value)
{
    size_t n = strlen(value);
    while (n > 0 && (value[n - 1] == ' ' || value[n - 1] == '\t'))
        n--;
    return n > 1 && value[n - 1] == 'x' && n < 70;
}

pd_status pd_scene_set(pd_scene *s, const char *key, const char *value, pd_diag *diag)
{
    if (!s || !key || !value)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_set: NULL %s", !s ? "scene" : !key ? "key" : "value");
    pd_scene next = *s;
    pd_status st = PD_ERR_USAGE;
    for (int i = 0; i < NNUMERIC && st == PD_ERR_USAGE; i++) {
        const numeric_key *k = &keys[i];
        if (strcmp(key, k->key) != 0)
            continue;
        double v;
        if (strchr(value, ':') && k->param < 0) {
            /* gravity sets the thresholds of rest, built once per run; a
             * feeder's is known. */
            st = pd_fail(diag, PD_ERR_PARSE, "%s: takes one value, not a range, got '%.40s'",
                         key, value);
        } else if (strchr(value, ':')) {
            st = parse_range(k, value, &next.range[k->param], diag);
        } else if (k->param == PD_PARAM_CONTACT_TIME && multiple_alone(value)) {
            /* "3x": the zero-width range 3x:3x, which every drop draws as 3
             * times its part's automatic duration (as posedrop fit sets it). */
            char range[160];
            snprintf(range, sizeof range, "%.70s:%.70s", value, value);
            st = parse_range(k, range, &next.range[k->param], diag);
        } else if (k->field == offsetof(pd_scene, contact_time) && strcmp(value, "auto") == 0) {
            next.contact_time = PD_CONTACT_TIME_AUTO;
            memset(&next.range[k->param], 0, sizeof next.range[k->param]);
            st = PD_OK;
        } else if ((st = read_number(key, &k->rule, value, &v, diag)) == PD_OK) {
            *field(&next, k) = v * k->scale;
            if (k->param >= 0)
                memset(&next.range[k->param], 0, sizeof next.range[k->param]);
        }
    }
    if (st == PD_ERR_USAGE && strcmp(key, "restitution_law") == 0) {
        st = PD_OK;
        if (strcmp(value, "poisson") == 0)
            next.law = PD_RESTITUTION_POISSON;
        else if (strcmp(value, "energetic") == 0)
            next.law = PD_RESTITUTION_ENERGETIC;
        else
            st = pd_fail(diag, PD_ERR_PARSE, "%s: expected poisson or energetic, got '%s'", key,
                         value);
    }
    if (st == PD_ERR_USAGE && strcmp(key, "initial") == 0) {
        st = PD_OK;
        if (strcmp(value, "uniform") == 0)
            next.initial = PD_INITIAL_UNIFORM;
        else if (strcmp(value, "bootstrap") == 0)
            next.initial = PD_INITIAL_BOOTSTRAP;
        else if (strcmp(value, "stationary") == 0)
            next.initial = PD_INITIAL_STATIONARY;
        else
            st = pd_fail(diag, PD_ERR_PARSE, "%s: expected uniform, bootstrap or stationary, "
                         "got '%s'", key, value);
    }
    if (st == PD_ERR_USAGE) {
        char known[256] = "";
        for (int i = 0; i < NKEYS; i++) {
            strcat(known, i ? ", " : "");
            strcat(known, scene_keys[i]);
        }
        return pd_fail(diag, PD_ERR_USAGE, "unknown scene setting '%s' (%s)", key, known);
    }
    /* The text was read by the rules of the table; the scene it makes is
     * checked by the one validator, as pd_sim_run checks it. */
    if (st == PD_OK)
        st = pd_scene_check(&next, diag);
    if (st == PD_OK)
        *s = next;
    return st;
}

/* A scene file is a handful of lines; anything this long is not one (and an
 * endless input like /dev/zero must end). */
enum { SCENE_MAX_BYTES = 1 << 20 };

/* Trims blanks at both ends in place. */
static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r'))
        s[--n] = '\0';
    return s;
}

/* The whole file, NUL-terminated, in *out (caller frees). */
static pd_status read_whole(const char *path, char **out, size_t *size, pd_diag *diag)
{
    errno = 0;
    FILE *f = pd_file_fopen_read(path);
    if (!f)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot open: %s", path,
                       errno ? strerror(errno) : "unknown error");
    struct stat sb;
    if (fstat(fileno(f), &sb) == 0 && S_ISDIR(sb.st_mode)) {
        fclose(f);
        return pd_fail(diag, PD_ERR_IO, "%s: is a directory, not a scene file", path);
    }
    char *buf = malloc(SCENE_MAX_BYTES + 2);
    if (!buf) {
        fclose(f);
        return pd_fail(diag, PD_ERR_NOMEM, "%s: out of memory", path);
    }
    errno = 0;
    size_t n = fread(buf, 1, SCENE_MAX_BYTES + 1, f);
    int err = ferror(f) ? (errno ? errno : EIO) : 0;
    pd_status st = err ? PD_OK : pd_file_check_fifo(fileno(f), n, path, diag);
    fclose(f);
    if (err) {
        free(buf);
        return pd_fail(diag, PD_ERR_IO, "%s: cannot read: %s", path, strerror(err));
    }
    if (st != PD_OK) {
        free(buf);
        return st;
    }
    if (n > SCENE_MAX_BYTES) {
        free(buf);
        return pd_fail(diag, PD_ERR_RANGE, "%s: longer than %d bytes: not a scene file", path,
                       SCENE_MAX_BYTES);
    }
    buf[n] = '\0';
    *out = buf;
    *size = n;
    return PD_OK;
}

/* Parses the lines of buf (size bytes, NUL-terminated at size, edited in
 * place) into scene; name is for messages. */
static pd_status parse_lines(char *buf, size_t size, const char *path, pd_scene *scene,
                             pd_diag *diag)
{
    pd_status st = PD_OK;
    pd_scene s = *scene; /* a failure leaves the caller's scene untouched */
    int set_on[NKEYS] = {0}; /* line of each key's setting, to refuse a second one */
    char *p = buf, *end = buf + size;
    /* Editors on some systems start UTF-8 text with a byte-order mark. */
    if (size >= 3 && memcmp(p, "\xEF\xBB\xBF", 3) == 0)
        p += 3;
    for (int lineno = 1; st == PD_OK && p < end; lineno++) {
        char *nl = memchr(p, '\n', (size_t)(end - p));
        char *stop = nl ? nl : end;
        if (memchr(p, '\0', (size_t)(stop - p))) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%d: a NUL byte: a scene file is text", path,
                         lineno);
            break;
        }
        *stop = '\0';
        char *line = p;
        p = stop + 1;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *text = trim(line);
        if (!*text)
            continue;
        char *eq = strchr(text, '=');
        if (!eq) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%d: expected 'key = value', found '%.60s'", path,
                         lineno, text);
            break;
        }
        *eq = '\0';
        char *key = trim(text), *value = trim(eq + 1);
        int k = key_index(key);
        if (k >= 0 && set_on[k]) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%d: %s is set a second time (first on line %d)",
                         path, lineno, key, set_on[k]);
            break;
        }
        pd_diag inner;
        pd_diag_init(&inner);
        st = pd_scene_set(&s, key, value, &inner);
        if (st != PD_OK)
            pd_fail(diag, st, "%s:%d: %s", path, lineno, inner.message);
        else
            set_on[k] = lineno;
    }
    if (st == PD_OK)
        *scene = s;
    return st;
}

pd_status pd_scene_read(const char *path, pd_scene *scene, pd_diag *diag)
{
    if (!path || !scene)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_read: NULL %s", path ? "scene" : "path");
    char *buf = NULL;
    size_t size = 0;
    pd_status st = read_whole(path, &buf, &size, diag);
    if (st == PD_OK)
        st = parse_lines(buf, size, path, scene, diag);
    free(buf);
    return st;
}

pd_status pd_scene_parse(const void *data, size_t size, const char *name, pd_scene *scene,
                         pd_diag *diag)
{
    if ((!data && size) || !scene)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_parse: NULL %s", scene ? "data" : "scene");
    if (size > SCENE_MAX_BYTES)
        return pd_fail(diag, PD_ERR_RANGE, "%s: longer than %d bytes: not a scene file",
                       name ? name : "<memory>", SCENE_MAX_BYTES);
    char *buf = malloc(size + 1);
    if (!buf)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    if (size)
        memcpy(buf, data, size);
    buf[size] = '\0';
    pd_status st = parse_lines(buf, size, name ? name : "<memory>", scene, diag);
    free(buf);
    return st;
}
