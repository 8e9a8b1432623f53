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

static void labels(vbuf *b, const viz_input *in, const viz_entry *e, double x, double y)
{
    char line[160], a[32], c[32], d[32];
    char colour[8];
    viz_entry_colour(e->number - 1, colour);
    char attrs[80];
    snprintf(attrs, sizeof attrs, "fill=\"%s\" stroke=\"#333333\" stroke-width=\"0.5\"", colour);
    viz_rect(b, x, y - 11, 12, 12, attrs);
    if (e->members > 1)
        snprintf(line, sizeof line, "Pose %d (%d symmetric)", e->number, e->members);
    else
        snprintf(line, sizeof line, "Pose %d", e->number);
    viz_text(b, x + 17, y, 14, "start", 1, "#111111", line);
    y += LINE_H;
    percent(a, sizeof a, e->p_qs);
    percent(c, sizeof c, e->p_pqs);
    snprintf(line, sizeof line, "QS %s, PQS %s", a, c);
    viz_text(b, x, y, 12.5, "start", 0, "#222222", line);
    if (e->has_dyn) {
        y += LINE_H;
        percent(a, sizeof a, e->p);
        percent(c, sizeof c, e->lo);
        percent(d, sizeof d, e->hi);
        snprintf(line, sizeof line, "%s %s [%s, %s]", in->engine ? in->engine : "drops", a, c, d);
        viz_text(b, x, y, 12.5, "start", 0, "#222222", line);
    }
    if (e->has_meas) {
        y += LINE_H;
        percent(a, sizeof a, e->mp);
        if (e->meas_ci) {
            percent(c, sizeof c, e->mlo);
            percent(d, sizeof d, e->mhi);
            snprintf(line, sizeof line, "measured %s [%s, %s]", a, c, d);
        } else {
            snprintf(line, sizeof line, "measured %s", a);
        }
        viz_text(b, x, y, 12.5, "start", 0, "#222222", line);
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
    /* At least two panels wide, so that the title and scale bar fit. */
    double w = (cols < 2 ? 2 : cols) * PANEL_W + 2 * GAP, h = TITLE_H + rows * panel_h + GAP;
    char title[512];
    snprintf(title, sizeof title, "Stable poses of %s%s", viz_base_name(in->name),
             in->class_of ? ", one panel per class" : "");
    viz_svg_open(b, standalone, w, h, title);
    vbuf_put(b, "<g class=\"gallery\">\n");
    viz_text(b, GAP, 22, 16, "start", 1, "#111111", title);
    /* The scale bar: a round length about a quarter of the part's size. */
    char len_label[32];
    double len = viz_nice_length(0.25 * in->part->size, len_label, sizeof len_label);
    double bx = w - GAP - scale * len;
    viz_xy(b, "<path d=\"M", bx, 36);
    viz_xy(b, " L", w - GAP, 36);
    viz_xy(b, " M", bx, 32);
    viz_xy(b, " L", bx, 40);
    viz_xy(b, " M", w - GAP, 32);
    viz_xy(b, " L", w - GAP, 40);
    vbuf_put(b, "\" fill=\"none\" stroke=\"#111111\" stroke-width=\"1.5\"/>\n");
    viz_text(b, bx - 6, 40, 12, "end", 0, "#111111", len_label);
    viz_text(b, GAP, 40, 11, "start", 0, "#555555",
             "Same scale in every panel. Red dashes: the resting facet; "
             "circle: the centre of mass.");
    for (int i = 0; i < n; i++) {
        double x0 = GAP + (i % cols) * PANEL_W, y0 = TITLE_H + (i / cols) * panel_h;
        vbuf_printf(b, "<g class=\"panel\" id=\"pose-%d\">\n<title>Pose %d</title>\n", e[i].number,
                    e[i].number);
        viz_pic_draw(b, in->part, &pics[i], &view, scale, x0 + 0.5 * PANEL_W,
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
