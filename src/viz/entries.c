/* entries.c: the rows the pictures show, eq. (16) and the entry colours. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

pd_status viz_entries(const viz_input *in, viz_entry **out, int *n, pd_diag *diag)
{
    const pd_static_result *res = in->res;
    int k = in->class_of ? in->nclasses : res->nposes;
    const viz_measured *m = in->measured;
    if (m && m->npose > k)
        return pd_fail(diag, PD_ERR_USAGE,
                       "%s: pose %d measured, but the part has %d %s", m->path, m->npose, k,
                       in->class_of ? "pose classes (--group)" : "stable poses");
    viz_entry *e = calloc((size_t)k + 1, sizeof *e);
    if (!e)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    for (int c = 0; c < k; c++)
        e[c].pose = -1;
    for (int i = 0; i < res->nposes; i++) {
        int c = in->class_of ? in->class_of[i] : i;
        if (e[c].pose < 0)
            e[c].pose = i;
        e[c].members++;
        e[c].p_qs += res->poses[i].p_qs;
        e[c].p_pqs += res->poses[i].p_pqs;
    }
    for (int c = 0; c < k; c++) {
        e[c].number = c + 1;
        if (in->sim) {
            e[c].has_dyn = 1;
            e[c].p = in->sim->p[c];
            e[c].lo = in->sim->ci_lo[c];
            e[c].hi = in->sim->ci_hi[c];
        }
        if (in->engines) {
            e[c].x = viz_engine_spread(in->engines, c);
            e[c].has_xc = e[c].x.ran > 0;
        }
        if (m) {
            e[c].has_meas = 1;
            e[c].mp = c < m->npose ? m->p[c] : 0.0;
            e[c].meas_ci = m->lo != NULL;
            if (m->lo) {
                e[c].mlo = c < m->npose ? m->lo[c] : 0.0;
                e[c].mhi = c < m->npose ? m->hi[c] : 0.0;
            }
        }
    }
    *out = e;
    *n = k;
    return PD_OK;
}

viz_spread viz_engine_spread(const viz_engines *x, int entry)
{
    viz_spread s = {0.0, 0.0, 0, 0};
    double min_hi = 0.0, max_lo = 0.0;
    for (int k = 0; k < VIZ_ENGINES; k++) {
        const pd_sim_result *r = x->sim[k];
        if (!r || r->n == 0)
            continue;
        double p = r->p[entry], lo = r->ci_lo[entry], hi = r->ci_hi[entry];
        if (s.ran++ == 0) {
            s.lo = s.hi = p;
            min_hi = hi;
            max_lo = lo;
        }
        s.lo = fmin(s.lo, p);
        s.hi = fmax(s.hi, p);
        min_hi = fmin(min_hi, hi);
        max_lo = fmax(max_lo, lo);
    }
    s.apart = s.ran > 1 && min_hi < max_lo;
    return s;
}

const char *viz_engine_label(int k)
{
    static const char *const names[VIZ_ENGINES] = {"impulse", "ODE", "Bullet"};
    return k >= 0 && k < VIZ_ENGINES ? names[k] : "?";
}

void viz_eq16(const viz_entry *e, int n, int which, double *e16, double *tv)
{
    double s16 = 0.0, stv = 0.0;
    for (int i = 0; i < n; i++) {
        double a = which == 0 ? e[i].p_qs : which == 1 ? e[i].p_pqs : e[i].p;
        double d = fabs(a - e[i].mp);
        s16 += e[i].mp * d;
        stv += d;
    }
    *e16 = 100.0 * s16;
    *tv = 50.0 * stv;
}

/* Ten hues that stay apart for most colour vision, then the same hues
 * darkened, and so on: entries beyond ten share a hue with one ten earlier,
 * told apart by their numbers. */
void viz_entry_colour(int i, char out[8])
{
    static const unsigned char base[10][3] = {
        {78, 121, 167}, {242, 142, 43}, {89, 161, 79}, {225, 87, 89}, {118, 183, 178},
        {237, 201, 72}, {176, 122, 161}, {255, 157, 167}, {156, 117, 95}, {186, 176, 172},
    };
    double dim = pow(0.72, (double)((i / 10) % 3));
    const unsigned char *c = base[i % 10];
    snprintf(out, 8, "#%02x%02x%02x", (unsigned)(c[0] * dim), (unsigned)(c[1] * dim),
             (unsigned)(c[2] * dim));
}

const char *viz_base_name(const char *path)
{
    if (!path)
        return "the part";
    const char *slash = strrchr(path, '/');
    return slash && slash[1] ? slash + 1 : path;
}

const char *viz_initial_name(pd_initial initial)
{
    static const char *const names[] = {"uniform", "bootstrap", "stationary"};
    return initial >= PD_INITIAL_UNIFORM && initial <= PD_INITIAL_STATIONARY ? names[initial] : "?";
}
