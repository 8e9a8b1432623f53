/* scene.c: the settings of a drop, their defaults (the paper's section 5.2)
 * and their text form, shared by scene files and the command line. */
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/text.h"
#include "posedrop/sim.h"

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
    s->contact_time = 5e-4; /* a plastic part on a rubber belt (docs/method.md) */
}

typedef struct {
    const char *key;
    size_t field;      /* offsetof the double in pd_scene */
    double lo, hi;     /* allowed range of the text value, inclusive */
    double scale;      /* text value times scale is stored (degrees -> rad) */
    const char *what;
} numeric_key;

/* Ranges: a drop needs a non-negative height and positive gravity; friction
 * beyond 10 is no longer a material (the tests go to 10); restitution above 1
 * would create energy; vibration is a tilt. The same table checks the text
 * (pd_scene_set) and a scene filled in by a program (pd_scene_check). */
static const numeric_key keys[] = {
    {"height", offsetof(pd_scene, height), 0.0, 1e3, 1.0, "a drop height in m, 0 to 1000"},
    {"belt_speed", offsetof(pd_scene, belt_speed), -1e3, 1e3, 1.0, "a speed in m/s, -1000 to 1000"},
    {"v", offsetof(pd_scene, belt_speed), -1e3, 1e3, 1.0, "a speed in m/s, -1000 to 1000"},
    {"mu", offsetof(pd_scene, mu), 0.0, 10.0, 1.0, "a friction coefficient from 0 to 10"},
    {"restitution", offsetof(pd_scene, restitution), 0.0, 1.0, 1.0, "a restitution from 0 to 1"},
    {"vibration", offsetof(pd_scene, vibration), 0.0, 180.0, M_PI / 180.0,
     "an angle in degrees, 0 to 180"},
    {"gravity", offsetof(pd_scene, gravity), 1e-3, 1e3, 1.0,
     "an acceleration in m/s^2, 0.001 to 1000"},
    {"contact_time", offsetof(pd_scene, contact_time), 0.0, 1.0, 1.0, "a duration in s, 0 to 1"},
};
enum { NKEYS = sizeof keys / sizeof keys[0] };

static double *field(pd_scene *s, const numeric_key *k)
{
    return (double *)(void *)((char *)s + k->field);
}

pd_status pd_scene_check(const pd_scene *scene, pd_diag *diag)
{
    if (!scene)
        return pd_fail(diag, PD_ERR_USAGE, "pd_scene_check: NULL scene");
    for (int i = 0; i < NKEYS; i++) {
        const numeric_key *k = &keys[i];
        double v = *field((pd_scene *)scene, k);
        /* The stored value is the text's times scale, rounded; rounding is
         * monotonic, so lo * scale and hi * scale bound exactly what
         * pd_scene_set accepts. */
        if (!isfinite(v))
            return pd_fail(diag, PD_ERR_NONFINITE, "scene %s is %g: expected %s", k->key,
                           v / k->scale, k->what);
        if (v < k->lo * k->scale || v > k->hi * k->scale)
            return pd_fail(diag, PD_ERR_RANGE, "scene %s is %.17g: expected %s", k->key,
                           v / k->scale, k->what);
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
    for (int i = 0; i < NKEYS; i++) {
        if (strcmp(key, keys[i].key) != 0)
            continue;
        double v;
        if (pd_parse_double(value, strlen(value), &v) != PD_NUM_OK)
            return pd_fail(diag, PD_ERR_PARSE, "%s: expected %s, got '%s'", key, keys[i].what, value);
        if (v < keys[i].lo || v > keys[i].hi)
            return pd_fail(diag, PD_ERR_RANGE, "%s: expected %s, got %s", key, keys[i].what, value);
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
    return pd_fail(diag, PD_ERR_USAGE,
                   "unknown scene setting '%s' (height, belt_speed, mu, restitution, "
                   "restitution_law, vibration, initial, gravity, contact_time)", key);
}

/* Trims blanks at both ends in place. */
static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t')
        s++;
    size_t n = strlen(s);
    while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t' || s[n - 1] == '\r' || s[n - 1] == '\n'))
        s[--n] = '\0';
    return s;
}

pd_status pd_scene_read(const char *path, pd_scene *scene, pd_diag *diag)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    pd_scene s = *scene; /* a failure leaves the caller's scene untouched */
    char line[1024];
    int lineno = 0;
    pd_status st = PD_OK;
    while (st == PD_OK && fgets(line, sizeof line, f)) {
        lineno++;
        if (!strchr(line, '\n') && !feof(f)) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%d: line longer than %d characters", path, lineno,
                         (int)sizeof line - 2);
            break;
        }
        char *hash = strchr(line, '#');
        if (hash)
            *hash = '\0';
        char *text = trim(line);
        if (!*text)
            continue;
        char *eq = strchr(text, '=');
        if (!eq) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%d: expected 'key = value', found '%s'", path,
                         lineno, text);
            break;
        }
        *eq = '\0';
        char *key = trim(text), *value = trim(eq + 1);
        pd_diag inner;
        pd_diag_init(&inner);
        st = pd_scene_set(&s, key, value, &inner);
        if (st != PD_OK)
            pd_fail(diag, st, "%s:%d: %s", path, lineno, inner.message);
    }
    if (st == PD_OK && ferror(f))
        st = pd_fail(diag, PD_ERR_IO, "%s: read error", path);
    fclose(f);
    if (st == PD_OK)
        *scene = s;
    return st;
}
