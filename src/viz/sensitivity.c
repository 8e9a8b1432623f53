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

enum { CELL_W = 150, ROW_H = 46, LEFT = 70, TOP = 64, BAR_H = 12 };

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
    viz_svg_open(b, standalone, w < 520 ? 520 : w, h, title);
    vbuf_put(b, "<g class=\"sensitivity\">\n");
    viz_text(b, 10, 22, 15, "start", 1, "#111111", title);
    viz_text(b, 10, 40, 11, "start", 0, "#555555",
             "bar: share of the pose's variance the parameter explains (first-order index, "
             "95% interval); below: p in the range's lower -> upper third");
    for (int col = 0; col < s->nparams; col++)
        viz_text(b, LEFT + col * CELL_W + CELL_W / 2.0, TOP - 6, 12, "middle", 1, "#111111",
                 human(s->param[col]));
    for (int pose = 0; pose < s->nposes; pose++) {
        double y = TOP + pose * ROW_H;
        char lab[96];
        snprintf(lab, sizeof lab, "%s %d", in->class_of ? "class" : "pose", pose + 1);
        viz_text(b, LEFT - 8, y + 16, 12, "end", 1, "#111111", lab);
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            double x = LEFT + col * CELL_W + 6, full = CELL_W - 12;
            viz_rect(b, x, y + 6, full, BAR_H, "fill=\"#f0f0f0\"");
            if (r->index > 0.0)
                viz_rect(b, x, y + 6, r->index * full, BAR_H,
                         r->index_lo > VIZ_SENS_DETECT ? "fill=\"#4e79a7\"" : "fill=\"#b7c6d8\"");
            viz_xy(b, "<path d=\"M", x + r->index_lo * full, y + 12);
            viz_xy(b, " L", x + r->index_hi * full, y + 12);
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
    const char *what = in->class_of ? "Class" : "Pose";
    vbuf_put(b, "<ul class=\"words\">\n");
    for (int pose = 0; pose < s->nposes; pose++) {
        int top = 0;
        double sum = 0.0;
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            if (r->index > row_of(s, pose, top)->index)
                top = col;
            if (r->index_lo > VIZ_SENS_DETECT)
                sum += r->index;
        }
        const pd_sensitivity_row *t = row_of(s, pose, top);
        vbuf_printf(b, "<li>%s %d: ", what, pose + 1);
        if (!(t->index_lo > VIZ_SENS_DETECT)) {
            vbuf_put(b, "no ranged parameter moves it measurably (every index's interval reaches "
                        "down to 1% of its variance); its variation is the drop's own "
                        "randomness.</li>\n");
            continue;
        }
        vbuf_printf(b, "depends %son %s (%.0f%% of its variance, 95%% %.0f-%.0f%%): %.1f%% of "
                       "the drops in the lower third of its range end here, %.1f%% in the "
                       "upper third.", t->index >= 0.5 ? "mostly " : "", human(t->param),
                    100 * t->index, 100 * t->index_lo, 100 * t->index_hi, 100 * t->p_low,
                    100 * t->p_high);
        int others = 0;
        for (int col = 0; col < s->nparams; col++) {
            const pd_sensitivity_row *r = row_of(s, pose, col);
            if (col == top || !(r->index_lo > VIZ_SENS_DETECT))
                continue;
            vbuf_printf(b, "%s %s (%.0f%%)", others++ ? "," : " Also", human(r->param),
                        100 * r->index);
        }
        vbuf_printf(b, "%s The ranged parameters alone explain %.0f%% of its variance; the rest "
                       "is the drop's own randomness (its orientation) and their joint "
                       "effects.</li>\n", others ? "." : "", 100 * sum);
    }
    vbuf_put(b, "</ul>\n");
}
