/* gallery.c: one panel per stable pose (or class), all at one scale. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

enum { PANEL_W = 240, DRAW_MAX_H = 200, LINE_H = 17, TITLE_H = 46, GAP = 10 };

/* The percent with one decimal, or "<0.1%" so that a small non-zero
 * probability never reads as none. */
static void percent(char *out, size_t size, double p)
{
    if (p > 0.0 && p < 0.0005)
        snprintf(out, size, "<0.1%%");
    else
        snprintf(out, size, "%.1f%%", 100.0 * p);
}

static int label_lines(const viz_entry *e)
{
    return 2 + e->has_dyn + e->has_meas;
}

/* Line k of an entry's label: its name (bold, 14 px, after its swatch), the
 * static estimates, the drops', the measured (12.5 px). */
static void label_line(const viz_input *in, const viz_entry *e, int k, char *line, size_t size)
{
    char a[32], c[32], d[32];
    if (k == 0) {
        if (e->members > 1)
            snprintf(line, size, "Pose %d (%d symmetric)", e->number, e->members);
        else
            snprintf(line, size, "Pose %d", e->number);
    } else if (k == 1) {
        percent(a, sizeof a, e->p_qs);
        percent(c, sizeof c, e->p_pqs);
        snprintf(line, size, "QS %s, PQS %s", a, c);
    } else if (k == 2 && e->has_dyn) {
        percent(a, sizeof a, e->p);
        percent(c, sizeof c, e->lo);
        percent(d, sizeof d, e->hi);
        snprintf(line, size, "%s %s [%s, %s]", in->engine ? in->engine : "drops", a, c, d);
    } else {
        percent(a, sizeof a, e->mp);
        if (e->meas_ci) {
            percent(c, sizeof c, e->mlo);
            percent(d, sizeof d, e->mhi);
            snprintf(line, size, "measured %s [%s, %s]", a, c, d);
        } else {
            snprintf(line, size, "measured %s", a);
        }
    }
}

enum { SWATCH = 17 }; /* the name's indent: its colour swatch and a gap */

/* The widest label line, from the label's left edge. */
static double label_width(const viz_input *in, const viz_entry *e)
{
    char line[160];
    double w = 0.0;
    for (int k = 0; k < label_lines(e); k++) {
        label_line(in, e, k, line, sizeof line);
        w = fmax(w, k == 0 ? SWATCH + viz_text_width(line, 14, 1) : viz_text_width(line, 12.5, 0));
    }
    return w;
}

static void labels(vbuf *b, const viz_input *in, const viz_entry *e, double x, double y)
{
    char line[160], colour[8], attrs[80];
    viz_entry_colour(e->number - 1, colour);
    snprintf(attrs, sizeof attrs, "fill=\"%s\" stroke=\"#333333\" stroke-width=\"0.5\"", colour);
    viz_rect(b, x, y - 11, 12, 12, attrs);
    for (int k = 0; k < label_lines(e); k++) {
        label_line(in, e, k, line, sizeof line);
        if (k == 0)
            viz_text(b, x + SWATCH, y, 14, "start", 1, "#111111", line);
        else
            viz_text(b, x, y + k * LINE_H, 12.5, "start", 0, "#222222", line);
    }
}

pd_status viz_gallery(const viz_input *in, int standalone, vbuf *b, pd_diag *diag)
{
    viz_entry *e;
    int n;
    pd_status st = viz_entries(in, &e, &n, diag);
    if (st != PD_OK)
        return st;
    viz_view view;
    viz_view_default(&view);
    double ew, eh;
    viz_pic *pics = viz_pics_build(in, e, n, &view, &ew, &eh);
    if (!pics) {
        free(e);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    }
    double scale = fmin((PANEL_W - 2.0 * GAP) / ew, DRAW_MAX_H / eh);
    double draw_h = ceil(scale * eh) + GAP;
    double label_h = LINE_H * label_lines(&e[0]) + GAP;
    int cols = n < 5 ? n : n <= 9 ? 3 + (n > 6) : 5;
    int rows = (n + cols - 1) / cols;
    double panel_h = draw_h + label_h;
    /* Panels wide enough for the widest label, with a gap to the next. */
    double panel_w = PANEL_W;
    for (int i = 0; i < n; i++)
        panel_w = fmax(panel_w, ceil(label_width(in, &e[i])) + 2 * GAP);
    char title[512], len_label[32];
    static const char *const subtitle = "Same scale in every panel. Red dashes: the resting "
                                        "facet; circle: the centre of mass.";
    snprintf(title, sizeof title, "Stable poses of %s%s", viz_base_name(in->name),
             in->class_of ? ", one panel per class" : "");
    /* The scale bar, a round length about a quarter of the part's size,
     * on the title's line at the right; the subtitle on a line of its own.
     * The picture is as wide as the panels, or as the title and bar, or
     * the subtitle, whichever is widest. */
    double len = viz_nice_length(0.25 * in->part->size, len_label, sizeof len_label);
    double bar = scale * len;
    double w = fmax(cols * panel_w + 2 * GAP,
                    fmax(GAP + viz_text_width(title, 16, 1) + 3 * GAP +
                             viz_text_width(len_label, 12, 0) + 6 + bar + GAP,
                         GAP + viz_text_width(subtitle, 11, 0) + GAP));
    w = ceil(w);
    double h = TITLE_H + rows * panel_h + GAP;
    viz_svg_open(b, standalone, w, h, title);
    vbuf_put(b, "<g class=\"gallery\">\n");
    viz_text(b, GAP, 22, 16, "start", 1, "#111111", title);
    double bx = w - GAP - bar;
    viz_xy(b, "<path class=\"scale-bar\" d=\"M", bx, 17);
    viz_xy(b, " L", w - GAP, 17);
    viz_xy(b, " M", bx, 13);
    viz_xy(b, " L", bx, 21);
    viz_xy(b, " M", w - GAP, 13);
    viz_xy(b, " L", w - GAP, 21);
    vbuf_put(b, "\" fill=\"none\" stroke=\"#111111\" stroke-width=\"1.5\"/>\n");
    viz_text(b, bx - 6, 21, 12, "end", 0, "#111111", len_label);
    viz_text(b, GAP, 40, 11, "start", 0, "#555555", subtitle);
    for (int i = 0; i < n; i++) {
        double x0 = GAP + (i % cols) * panel_w, y0 = TITLE_H + (i / cols) * panel_h;
        vbuf_printf(b, "<g class=\"panel\" id=\"pose-%d\">\n<title>Pose %d</title>\n", e[i].number,
                    e[i].number);
        viz_pic_draw(b, in->part, &pics[i], &view, scale, x0 + 0.5 * panel_w,
                     y0 + 0.5 * draw_h, 1);
        labels(b, in, &e[i], x0 + GAP, y0 + draw_h + LINE_H - 2);
        vbuf_put(b, "</g>\n");
    }
    vbuf_put(b, "</g>\n");
    viz_svg_close(b);
    viz_pics_free(pics, n);
    free(e);
    return b->failed ? pd_fail(diag, PD_ERR_NOMEM, "out of memory") : PD_OK;
}
