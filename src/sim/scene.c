/* scene.c: the settings of a drop, their defaults (the paper's section 5.2)
 * and their text form, shared by scene files and the command line. */
#include <errno.h>
#include <math.h>
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
    double *field;
    double lo, hi;     /* allowed range, inclusive */
    double scale;      /* text value times scale is stored (degrees -> rad) */
    const char *what;
} numeric_key;

pd_status pd_scene_set(pd_scene *s, const char *key, const char *value, pd_diag *diag)
{
    /* Ranges: a drop needs a non-negative height and positive gravity;
     * friction beyond 10 is no longer a material (the tests go to 10);
     * restitution above 1 would create energy; vibration is a tilt. */
    const numeric_key keys[] = {
        {"height", &s->height, 0.0, 1e3, 1.0, "a drop height in m, 0 to 1000"},
        {"belt_speed", &s->belt_speed, -1e3, 1e3, 1.0, "a speed in m/s"},
        {"v", &s->belt_speed, -1e3, 1e3, 1.0, "a speed in m/s"},
        {"mu", &s->mu, 0.0, 10.0, 1.0, "a friction coefficient from 0 to 10"},
        {"restitution", &s->restitution, 0.0, 1.0, 1.0, "a restitution from 0 to 1"},
        {"vibration", &s->vibration, 0.0, 180.0, M_PI / 180.0, "an angle in degrees, 0 to 180"},
        {"gravity", &s->gravity, 1e-3, 1e3, 1.0, "an acceleration in m/s^2, 0.001 to 1000"},
        {"contact_time", &s->contact_time, 0.0, 1.0, 1.0, "a duration in s, 0 to 1"},
    };
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++) {
        if (strcmp(key, keys[i].key) != 0)
            continue;
        double v;
        if (pd_parse_double(value, strlen(value), &v) != PD_NUM_OK)
            return pd_fail(diag, PD_ERR_PARSE, "%s: expected %s, got '%s'", key, keys[i].what, value);
        if (v < keys[i].lo || v > keys[i].hi)
            return pd_fail(diag, PD_ERR_RANGE, "%s: expected %s, got %s", key, keys[i].what, value);
        *keys[i].field = v * keys[i].scale;
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
