/* sensitivity.c: what each ranged scene parameter moves, as a chart (one
 * row per pose, one column per parameter: the effect, how far the pose's
 * probability moves across the range, as a bar from the cell's middle with
 * its interval, the thirds and the index beneath) and in words a designer
 * acts on ("class 2: friction moves it by -8 points"), for the report. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "base/fail.h"
#include "viz/viz_const.h"
#include "viz/viz_internal.h"

enum { CELL_W = 150, ROW_H = 46, LEFT = 70, TOP = 78, BAR_H = 12 };

/* The parameter as a designer names it. */
static const char *human(pd_scene_param p)
{
    static const char *const names[PD_NPARAMS] = {"drop height", "belt speed", "friction",
                                                  "restitution", "vibration", "contact time",
                                                  "tumble"};
    return (unsigned)p < PD_NPARAMS ? names[p] : "?";
}

static const pd_sensitivity_row *row_of(const pd_sensitivity *s, int pose, int col)
{
    return &s->rows[(size_t)pose * (size_t)s->nparams + (size_t)col];
}

/* Whether a parameter moves a pose beyond the drops' noise: its effect's
 * 95% interval is clear of 0, or its index's is clear of VIZ_SENS_DETECT
 * (a pose that peaks or dips inside the range, thirds alike). */
static int moves(const pd_sensitivity_row *r)
{
    return r->effect_lo > 0.0 || r->effect_hi < 0.0 || r->index_lo > VIZ_SENS_DETECT;
}

/* The most a parameter can move a pose by its interval: the interval's
 * end furthest from 0. */
static double bound(const pd_sensitivity_row *r)
{
    return fmax(fabs(r->effect_lo), fabs(r->effect_hi));
}

pd_status viz_sensitivity(const viz_input *in, int standalone, vbuf *b, pd_diag *diag)
{
    const pd_sensitivity *s = in->sensitivity;
    if (!s || s->nparams == 0)
        return pd_fail(diag, PD_ERR_USAGE, "no ranged parameter to show");
    double w = LEFT + s->nparams * CELL_W + 20, h = TOP + s->nposes * ROW_H + 30;
    char title[512];
    snprintf(title, sizeof title, "What moves each pose of %s (%ld drops, initial %s)",
             viz_base_name(in->name), s->n,
             in->scene ? viz_initial_name(in->scene->initial) : "?");
    viz_svg_open(b, standalone, w < 620 ? 620 : w, h, title);
    vbuf_put(b, "<g class=\"sensitivity\">\n");
    viz_text(b, 10, 22, 15, "start", 1, "#111111", title);
    /* The bars fill half a cell at the first of 0.1, 0.2, 0.5, 1 that
     * holds every interval. */
    double top = 0.0, full_effect = 1.0;
    for (int i = 0; i < s->nposes * s->nparams; i++)
        top = fmax(top, bound(&s->rows[i]));
    static const double scales[] = {0.1, 0.2, 0.5, 1.0};
    for (int i = 3; i >= 0; i--)
        if (top <= scales[i])
            full_effect = scales[i];
    char sub[200];
    snprintf(sub, sizeof sub, "bar: the effect, p in the range's upper third less its lower "
             "(half a cell: %g points), 95%% interval;", 100 * full_effect);
    viz_text(b, 10, 38, 11, "start", 0, "#555555", sub);
    viz_text(b, 10, 51, 11, "start", 0, "#555555",
             "dark: it moves the pose. Below: p lower -> upper third, first-order index.");
    for (int col = 0; col < s->nparams; col++)
        viz_text(b, LEFT + col * CELL_W + CELL_W / 2.0, TOP - 6, 12, "middle", 1, "#111111",
                 human(s->param[col]));
    for (int pose = 0; pose < s->nposes; pose++) {
        double y = TOP + pose * ROW_H;
        char lab[96];
        snprintf(lab, sizeof lab, "pose %d", pose + 1); /* the gallery's word, classes too */
        viz_text(b, LEFT - 8, y + 16, 12, "end", 1, "#111111", lab);
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            double x = LEFT + col * CELL_W + 6, full = CELL_W - 12;
            viz_rect(b, x, y + 6, full, BAR_H, "fill=\"#f0f0f0\"");
            double mid = x + full / 2.0, u = full / 2.0 / full_effect;
            if (r->effect != 0.0)
                viz_rect(b, fmin(mid, mid + r->effect * u), y + 6, fabs(r->effect) * u, BAR_H,
                         moves(r) ? "fill=\"#4e79a7\"" : "fill=\"#b7c6d8\"");
            viz_xy(b, "<path d=\"M", mid + r->effect_lo * u, y + 12);
            viz_xy(b, " L", mid + r->effect_hi * u, y + 12);
            vbuf_put(b, "\" stroke=\"#111111\" stroke-width=\"1.2\"/>\n");
            snprintf(lab, sizeof lab, "%+.1f pts [%+.1f, %+.1f]", 100 * r->effect,
                     100 * r->effect_lo, 100 * r->effect_hi);
            viz_text(b, x, y + 30, 10, "start", 0, "#111111", lab);
            snprintf(lab, sizeof lab, "p %.0f%% -> %.0f%%, index %.2f", 100 * r->p_low,
                     100 * r->p_high, r->index);
            viz_text(b, x, y + 41, 10, "start", 0, "#333333", lab);
        }
    }
    vbuf_put(b, "</g>\n");
    viz_svg_close(b);
    if (b->failed)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    return PD_OK;
}

void viz_sensitivity_words(vbuf *b, const viz_input *in)
{
    const pd_sensitivity *s = in->sensitivity;
    if (!s || s->nparams == 0)
        return;
    const char *what = "Pose"; /* the gallery's word, classes too */
    vbuf_put(b, "<ul class=\"words\">\n");
    for (int pose = 0; pose < s->nposes; pose++) {
        /* The parameters that move it, by the size of their effect. */
        int order[PD_NPARAMS], n = 0;
        double most = 0.0; /* the furthest bound of those that do not */
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            if (!moves(r)) {
                most = fmax(most, bound(r));
                continue;
            }
            int at = n++;
            while (at > 0 && fabs(row_of(s, pose, order[at - 1])->effect) < fabs(r->effect)) {
                order[at] = order[at - 1];
                at--;
            }
            order[at] = col;
        }
        vbuf_printf(b, "<li>%s %d: ", what, pose + 1);
        if (n == 0) {
            vbuf_printf(b, "no ranged parameter moves it by more than %.1f points (the widest "
                           "end of its effects' 95%% intervals, %ld drops); it is decided by how "
                           "the part happens to fall.", 100 * most, s->n);
        } else {
            const pd_sensitivity_row *t = row_of(s, pose, order[0]);
            int mostly = n > 1 && fabs(t->effect) >= 2.0 * fabs(row_of(s, pose, order[1])->effect);
            vbuf_printf(b, "%s moves it %sby %+.1f points across its range (95%% %+.1f to %+.1f): "
                           "%.1f%% of the drops in the lower third of the range end here, %.1f%% "
                           "in the upper third (index %.2f).",
                        human(t->param), mostly ? "most, " : "", 100 * t->effect,
                        100 * t->effect_lo, 100 * t->effect_hi, 100 * t->p_low, 100 * t->p_high,
                        t->index);
            for (int i = 1; i < n; i++) {
                const pd_sensitivity_row *r = row_of(s, pose, order[i]);
                vbuf_printf(b, "%s %s %+.1f points (%+.1f to %+.1f)", i > 1 ? "," : " Also",
                            human(r->param), 100 * r->effect, 100 * r->effect_lo,
                            100 * r->effect_hi);
            }
            vbuf_printf(b, "%s", n > 1 ? "." : "");
            if (n < s->nparams)
                vbuf_printf(b, " No other parameter moves it by more than %.1f points.",
                            100 * most);
        }
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            if (r->interacts < 0)
                continue;
            vbuf_printf(b, " The effect of %s depends on %s: %+.1f, %+.1f and %+.1f points in "
                           "its lower, middle and upper thirds.",
                        human(r->param), human((pd_scene_param)r->interacts),
                        100 * r->effect_in[0], 100 * r->effect_in[1], 100 * r->effect_in[2]);
        }
        vbuf_put(b, "</li>\n");
    }
    vbuf_printf(b, "<li>These %ld drops resolve an effect to %.1f points (the widest half "
                   "interval); four times the drops halve it. Of the %d pairs of parameters "
                   "tested for an interaction, about 5%% are flagged by chance alone.</li>\n",
                s->n, 100 * s->resolution, s->interaction_tests);
    vbuf_put(b, "</ul>\n");
}
