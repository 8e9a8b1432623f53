/* scene.c: the settings of a drop, their defaults (the paper's section 5.2)
 * and their text form, shared by scene files and the command line. */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "base/fail.h"
#include "base/number.h"
#include "posedrop/sim.h"
#include "sim/scene.h"

void pd_scene_default(pd_scene *s)
{
    s->height = 0.12;
    s->belt_speed = 0.05;
    s->mu = 0.3;
    s->restitution = 0.3;
    s->law = PD_RESTITUTION_POISSON;
    s->vibration = 1.5 * M_PI / 180.0;
    s->initial = PD_INITIAL_UNIFORM;
    s->gravity = 9.81;
    s->contact_time = PD_CONTACT_TIME_AUTO;
}

/* The Hertz estimate for the paper's scene (docs/contact.md) and the part
 * it was made for, a 1 cm cube: its diagonal and volume. */
#define CONTACT_T_REF 5e-4
#define CONTACT_SIZE_REF (0.01 * 1.7320508075688772935)
#define CONTACT_VOLUME_REF 1e-6

double pd_contact_time_auto(double size)
{
    return CONTACT_T_REF * size / CONTACT_SIZE_REF;
}

double pd_contact_time_auto_part(const pd_part *part)
{
    /* A needle's mass is far below L^3: by its length alone a 1 m needle
     * 1 mm thick got a 29 ms contact, whose static compression (about
     * g T^2 / 13) sank it deeper than its thickness and kept every drop
     * from settling. Powers taken apart so that no product of lengths
     * leaves the doubles over the supported sizes. */
    double volume = part->mass_known ? part->mass.volume : part->hull->volume;
    return CONTACT_T_REF * pow(volume / CONTACT_VOLUME_REF, 0.4) *
           pow(CONTACT_SIZE_REF / part->size, 0.2);
}

typedef struct {
    const char *key;
    size_t field;  /* offsetof the double in pd_scene */
    double scale;  /* text value times scale is stored (degrees -> rad) */
    pd_num_rule rule;
} numeric_key;

/* Ranges: a drop needs a non-negative height and positive gravity; friction
 * beyond 10 is no longer a material (the tests go to 10); restitution above 1
 * would create energy; vibration is a tilt. The same table checks the text
 * (pd_scene_set) and a scene filled in by a program (pd_scene_check). */
#define REAL(what, lo, hi) {what, 0, lo, hi, 0, 0, 0, 0}
static const numeric_key keys[] = {
    {"height", offsetof(pd_scene, height), 1.0, REAL("a drop height in m", 0.0, 1e3)},
    {"belt_speed", offsetof(pd_scene, belt_speed), 1.0, REAL("a belt speed in m/s", -1e3, 1e3)},
    {"mu", offsetof(pd_scene, mu), 1.0, REAL("a friction coefficient", 0.0, 10.0)},
    {"restitution", offsetof(pd_scene, restitution), 1.0, REAL("a restitution", 0.0, 1.0)},
    {"vibration", offsetof(pd_scene, vibration), M_PI / 180.0,
     REAL("an angle in degrees", 0.0, 180.0)},
    {"gravity", offsetof(pd_scene, gravity), 1.0, REAL("an acceleration in m/s^2", 1e-3, 1e3)},
    {"contact_time", offsetof(pd_scene, contact_time), 1.0, REAL("a duration in s", 0.0, 1.0)},
};
enum { NNUMERIC = sizeof keys / sizeof keys[0] };

/* Every key a scene accepts, for messages and duplicate checks. */
static const char *const scene_keys[] = {"height", "belt_speed", "mu", "restitution",
                                         "restitution_law", "vibration", "initial", "gravity",
                                         "contact_time"};
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

pd_status pd_scene_check(const pd_scene *scene, pd_diag *diag)
{
    if (!scene)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_check: NULL scene");
    for (int i = 0; i < NNUMERIC; i++) {
        const numeric_key *k = &keys[i];
        double v = *field((pd_scene *)scene, k);
        if (k->field == offsetof(pd_scene, contact_time) && v == PD_CONTACT_TIME_AUTO)
            continue;
        /* The stored value is the text's times scale, rounded; rounding is
         * monotonic, so lo * scale and hi * scale bound exactly what
         * pd_scene_set accepts. The message is the text's, in its unit. */
        int bad = !isfinite(v) ? PD_NUM_NONFINITE
                  : v < k->rule.lo * k->scale || v > k->rule.hi * k->scale ? PD_NUM_RANGE
                                                                           : PD_NUM_OK;
        if (bad != PD_NUM_OK) {
            char text[32], msg[PD_DIAG_MESSAGE_LEN];
            snprintf(text, sizeof text, "%.17g", v / k->scale);
            pd_num_message(msg, sizeof msg, &k->rule, text, bad);
            return pd_fail(diag, bad == PD_NUM_RANGE ? PD_ERR_RANGE : PD_ERR_NONFINITE,
                           "scene %s: %s", k->key, msg);
        }
    }
    if ((unsigned)scene->law > (unsigned)PD_RESTITUTION_ENERGETIC)
        return pd_fail(diag, PD_ERR_RANGE, "scene restitution_law is %d: expected "
                       "PD_RESTITUTION_POISSON or PD_RESTITUTION_ENERGETIC", (int)scene->law);
    if ((unsigned)scene->initial > (unsigned)PD_INITIAL_STATIONARY)
        return pd_fail(diag, PD_ERR_RANGE, "scene initial is %d: expected PD_INITIAL_UNIFORM, "
                       "PD_INITIAL_BOOTSTRAP or PD_INITIAL_STATIONARY", (int)scene->initial);
    return PD_OK;
}

pd_status pd_scene_set(pd_scene *s, const char *key, const char *value, pd_diag *diag)
{
    if (!s || !key || !value)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_set: NULL %s", !s ? "scene" : !key ? "key" : "value");
    for (int i = 0; i < NNUMERIC; i++) {
        if (strcmp(key, keys[i].key) != 0)
            continue;
        if (keys[i].field == offsetof(pd_scene, contact_time) && strcmp(value, "auto") == 0) {
            s->contact_time = PD_CONTACT_TIME_AUTO;
            return PD_OK;
        }
        double v;
        int rc = pd_num_read(&keys[i].rule, value, &v, NULL);
        if (rc != PD_NUM_OK) {
            char msg[PD_DIAG_MESSAGE_LEN];
            pd_num_message(msg, sizeof msg, &keys[i].rule, value, rc);
            return pd_fail(diag, rc == PD_NUM_BAD || rc == PD_NUM_NONFINITE ? PD_ERR_PARSE
                                                                             : PD_ERR_RANGE,
                           "%s: %s", key, msg);
        }
        *field(s, &keys[i]) = v * keys[i].scale;
        return PD_OK;
    }
    if (strcmp(key, "restitution_law") == 0) {
        if (strcmp(value, "poisson") == 0)
            s->law = PD_RESTITUTION_POISSON;
        else if (strcmp(value, "energetic") == 0)
            s->law = PD_RESTITUTION_ENERGETIC;
        else
            return pd_fail(diag, PD_ERR_PARSE, "%s: expected poisson or energetic, got '%s'", key,
                           value);
        return PD_OK;
    }
    if (strcmp(key, "initial") == 0) {
        if (strcmp(value, "uniform") == 0)
            s->initial = PD_INITIAL_UNIFORM;
        else if (strcmp(value, "bootstrap") == 0)
            s->initial = PD_INITIAL_BOOTSTRAP;
        else if (strcmp(value, "stationary") == 0)
            s->initial = PD_INITIAL_STATIONARY;
        else
            return pd_fail(diag, PD_ERR_PARSE, "%s: expected uniform, bootstrap or stationary, "
                           "got '%s'", key, value);
        return PD_OK;
    }
    char known[256] = "";
    for (int i = 0; i < NKEYS; i++) {
        strcat(known, i ? ", " : "");
        strcat(known, scene_keys[i]);
    }
    return pd_fail(diag, PD_ERR_USAGE, "unknown scene setting '%s' (%s)", key, known);
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
    FILE *f = fopen(path, "rb");
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
    fclose(f);
    if (err) {
        free(buf);
        return pd_fail(diag, PD_ERR_IO, "%s: cannot read: %s", path, strerror(err));
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
