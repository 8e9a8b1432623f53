/* sensitivity.c: what each ranged scene parameter moves, as a chart (one
 * row per pose, one column per parameter: the first-order index as a bar
 * with its interval, the pose's probability in the range's lower and upper
 * thirds beneath) and in words a designer acts on ("pose 2 depends mostly
 * on friction"), for the report. */
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

/* Whether a parameter moves a pose beyond the drops' noise: its lower and
 * upper thirds' 95% intervals are apart, or its index's interval is clear
 * of VIZ_SENS_DETECT. */
static int moves(const pd_sensitivity_row *r)
{
    return r->p_low_hi < r->p_high_lo || r->p_high_hi < r->p_low_lo ||
           r->index_lo > VIZ_SENS_DETECT;
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
    /* A pose indicator's index is small even for a parameter that moves
     * it a lot (its variance is mostly the fall's own randomness), so the
     * bars fill at the first of 0.1, 0.2, 0.5, 1 that holds every interval. */
    double top = 0.0, full_index = 1.0;
    for (int i = 0; i < s->nposes * s->nparams; i++)
        top = fmax(top, s->rows[i].index_hi);
    static const double scales[] = {0.1, 0.2, 0.5, 1.0};
    for (int i = 3; i >= 0; i--)
        if (top <= scales[i])
            full_index = scales[i];
    char sub[160];
    snprintf(sub, sizeof sub, "bar: first-order index, the share of the pose's variance the "
             "parameter explains (a full bar: %g), 95%% interval;", full_index);
    viz_text(b, 10, 38, 11, "start", 0, "#555555", sub);
    viz_text(b, 10, 51, 11, "start", 0, "#555555",
             "dark: it moves the pose. Below: p in the range's lower -> upper third.");
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
            double u = full / full_index;
            if (r->index > 0.0)
                viz_rect(b, x, y + 6, r->index * u, BAR_H,
                         moves(r) ? "fill=\"#4e79a7\"" : "fill=\"#b7c6d8\"");
            viz_xy(b, "<path d=\"M", x + r->index_lo * u, y + 12);
            viz_xy(b, " L", x + r->index_hi * u, y + 12);
            vbuf_put(b, "\" stroke=\"#111111\" stroke-width=\"1.2\"/>\n");
            snprintf(lab, sizeof lab, "%.2f [%.2f, %.2f]", r->index, r->index_lo, r->index_hi);
            viz_text(b, x, y + 30, 10, "start", 0, "#111111", lab);
            snprintf(lab, sizeof lab, "p %.0f%% -> %.0f%%", 100 * r->p_low, 100 * r->p_high);
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
        /* The parameters that move it, by index. */
        int order[PD_NPARAMS], n = 0;
        for (int col = 0; col < s->nparams; col++) {
            if (!moves(row_of(s, pose, col)))
                continue;
            int at = n++;
            while (at > 0 && row_of(s, pose, order[at - 1])->index < row_of(s, pose, col)->index) {
                order[at] = order[at - 1];
                at--;
            }
            order[at] = col;
        }
        vbuf_printf(b, "<li>%s %d: ", what, pose + 1);
        if (n == 0) {
            vbuf_printf(b, "no ranged parameter moves it beyond the noise of %ld drops; it "
                           "is decided by how the part happens to fall.</li>\n", s->n);
            continue;
        }
        const pd_sensitivity_row *t = row_of(s, pose, order[0]);
        int mostly = n == 1 || t->index >= 2.0 * row_of(s, pose, order[1])->index;
        vbuf_printf(b, "depends %son %s: %.1f%% of the drops in the lower third of its range "
                       "end here, %.1f%% in the upper third (index %.2f, 95%% %.2f-%.2f).",
                    mostly ? "mostly " : "", human(t->param), 100 * t->p_low, 100 * t->p_high,
                    t->index, t->index_lo, t->index_hi);
        for (int i = 1; i < n; i++) {
            const pd_sensitivity_row *r = row_of(s, pose, order[i]);
            vbuf_printf(b, "%s %s (%.1f%% to %.1f%%)", i > 1 ? "," : " Also", human(r->param),
                        100 * r->p_low, 100 * r->p_high);
        }
        vbuf_printf(b, "%s</li>\n", n > 1 ? "." : "");
    }
    vbuf_put(b, "</ul>\n");
}
