/* chart.c: the estimates as grouped bars, one group per pose, with the 95%
 * intervals as whiskers and each pose's thumbnail under its group. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

enum { BAR_W = 16, BAR_GAP = 2, GROUP_GAP = 22, THUMB = 80, PLOT_H = 300, LEFT = 58,
       RIGHT = 16, TOP = 40, LEGEND_LINE = 18 };
/* Past this width the groups wrap onto rows, each with its own axis: a
 * laptop's page (the report's body is at most 1240 px) shows the chart at
 * full size, its 11-12 px text readable, where 34 poses in one row made it
 * 3542 wide and a browser scaled its text to 4 px. */
#define WRAP_W 1200.0
/* A row: the plot, the pose numbers and thumbnails under it, a gap. */
#define ROW_H (PLOT_H + 22.0 + THUMB + 14.0 + 16.0)

typedef struct {
    const char *name;
    const char *colour;
} series;

/* The height of the axis: the next round step above the highest bar or
 * whisker, so that nothing is clipped. */
static double axis_top(const viz_entry *e, int n, double *step)
{
    double top = 0.0;
    for (int i = 0; i < n; i++) {
        top = fmax(top, fmax(e[i].p_qs, e[i].p_pqs));
        if (e[i].has_dyn)
            top = fmax(top, fmax(e[i].p, e[i].hi));
        if (e[i].has_xc)
            top = fmax(top, e[i].x.hi);
        if (e[i].has_meas)
            top = fmax(top, e[i].meas_ci ? fmax(e[i].mp, e[i].mhi) : e[i].mp);
    }
    top = fmin(fmax(top, 0.05), 1.0);
    *step = top > 0.5 ? 0.1 : top > 0.2 ? 0.05 : top > 0.1 ? 0.02 : 0.01;
    return fmin(1.0, ceil(top / *step - 1e-9) * *step);
}

/* A series' fill: greys, from light (QS) to dark (drops), and the measured
 * distribution white with a dark outline. Colours in a report mean poses
 * (the gallery's and the sphere map's, viz_entry_colour), so the series
 * that stand beside them take none. */
static void fill_attrs(const char *colour, char *attrs, size_t size)
{
    snprintf(attrs, size, "fill=\"%s\"%s", colour,
             colour[1] == 'f' ? " stroke=\"#111111\" stroke-width=\"1\"" : "");
}

static void bar(vbuf *b, double x, double y0, double hpx, const char *colour)
{
    char attrs[80];
    fill_attrs(colour, attrs, sizeof attrs);
    viz_rect(b, x, y0 - hpx, BAR_W, hpx, attrs);
}

/* The engines' range (--crosscheck) over the drops' bar: a box from the
 * lowest engine's p to the highest's, a little wider than the bar, so that
 * the bar's own top and whisker show through it. */
static const char *const band_attrs =
    "fill=\"#111111\" fill-opacity=\"0.14\" stroke=\"#111111\" stroke-width=\"1.2\" "
    "stroke-dasharray=\"3 2\"";

static void band(vbuf *b, double xc, double ylo, double yhi)
{
    /* A range of zero height still shows, as a line. */
    viz_rect(b, xc - BAR_W / 2.0 - 3, yhi, BAR_W + 6, fmax(ylo - yhi, 0.0), band_attrs);
}

static void whisker(vbuf *b, double xc, double ylo, double yhi)
{
    viz_xy(b, "<path d=\"M", xc, ylo);
    viz_xy(b, " L", xc, yhi);
    viz_xy(b, " M", xc - 4, ylo);
    viz_xy(b, " L", xc + 4, ylo);
    viz_xy(b, " M", xc - 4, yhi);
    viz_xy(b, " L", xc + 4, yhi);
    vbuf_put(b, "\" fill=\"none\" stroke=\"#111111\" stroke-width=\"1.2\"/>\n");
}

/* The legend's line for series sr (which: 0 QS, 1 PQS, 2 drops, 3
 * measured): its name; with a measured distribution, each estimate's eq.
 * (16) error and total variation against it. */
static void legend_line(const viz_input *in, const viz_entry *e, int n, const series *sr,
                        int which, char *line, size_t size)
{
    if (e[0].has_meas && which < 3) {
        double e16, tv;
        viz_eq16(e, n, which, &e16, &tv);
        snprintf(line, size, "%s: eq. (16) error %.2f, total variation %.1f%%", sr->name, e16, tv);
    } else if (which == 3) {
        if (in->measured->n)
            snprintf(line, size, "measured: %ld observations (%s)", in->measured->n,
                     viz_base_name(in->measured->path));
        else
            snprintf(line, size, "measured (%s; p without n: no interval)",
                     viz_base_name(in->measured->path));
    } else {
        snprintf(line, size, "%s", sr->name);
    }
}

pd_status viz_chart(const viz_input *in, int standalone, vbuf *b, pd_diag *diag)
{
    viz_entry *e;
    int n;
    pd_status st = viz_entries(in, &e, &n, diag);
    if (st != PD_OK)
        return st;
    series s[4] = {{"QS", "#c8c8c8"}, {"PQS", "#8e8e8e"}, {NULL, "#4a4a4a"}, {"measured", "#ffffff"}};
    char dyn_name[96];
    int has_dyn = e[0].has_dyn, has_meas = e[0].has_meas;
    if (has_dyn) {
        snprintf(dyn_name, sizeof dyn_name, "%s, %ld drops%s%s", in->engine ? in->engine : "drops",
                 in->sim->n, in->scene ? ", initial " : "",
                 in->scene ? viz_initial_name(in->scene->initial) : "");
        s[2].name = dyn_name;
    }
    int nser = 2 + has_dyn + has_meas;
    int which[4] = {0, 1, 2, 3};
    if (!has_dyn)
        which[2] = 3;
    int has_xc = has_dyn && e[0].has_xc;
    int legend_rows = nser + has_xc;
    double legend_h = legend_rows * LEGEND_LINE + 8;
    char title[512], legend[5][256];
    /* An interrupted run's chart says so where it is seen, as its CSV does. */
    snprintf(title, sizeof title, "Pose probabilities of %s%s%s", viz_base_name(in->name),
             in->class_of ? ", by class" : "",
             in->sim && in->sim->partial ? " (interrupted: partial)" : "");
    const char *whiskers = has_dyn || (has_meas && e[0].meas_ci) ? "whiskers: 95% intervals" : "";
    const char *caption = in->class_of
                              ? "pose class (as numbered by --group), drawn as in the gallery"
                              : "pose (as numbered in the output), drawn as in the gallery";
    for (int k = 0; k < nser; k++)
        legend_line(in, e, n, &s[which[k]], which[k], legend[k], sizeof legend[k]);
    if (has_xc) {
        int apart = 0;
        for (int i = 0; i < n; i++)
            apart += e[i].x.apart;
        snprintf(legend[nser], sizeof legend[nser], "dashed box: the range across the engines "
                 "(impulse, ODE, Bullet; same releases)%s", apart ? "; apart beyond their "
                 "95% intervals where marked !" : "");
    }
    /* As wide as the bars need, or as the title and the whiskers' note, the
     * legend or the caption (centred under the plot), whichever is widest;
     * the groups then share the plot's width. */
    double group_min = fmax(nser * (BAR_W + BAR_GAP), THUMB) + GROUP_GAP;
    int per_row = (int)fmax(1.0, floor((WRAP_W - LEFT - RIGHT) / group_min));
    if (per_row > n)
        per_row = n;
    int nrows = (n + per_row - 1) / per_row;
    double w = fmax(LEFT + per_row * group_min + RIGHT, 640);
    w = fmax(w, 10 + viz_text_width(title, 16, 1) + 20 + viz_text_width(whiskers, 11, 0) + RIGHT);
    for (int k = 0; k < nser + has_xc; k++)
        w = fmax(w, LEFT + 18 + viz_text_width(legend[k], 12, 0) + RIGHT);
    w = ceil(fmax(w, LEFT + viz_text_width(caption, 11, 0) + LEFT));
    double plot_w = w - LEFT - RIGHT, group_w = plot_w / per_row;
    double h = TOP + legend_h + nrows * ROW_H - 16.0;
    viz_svg_open(b, standalone, w, h, title);
    vbuf_put(b, "<g class=\"chart\">\n");
    viz_text(b, 10, 22, 16, "start", 1, "#111111", title);
    for (int k = 0; k < nser; k++) {
        double y = TOP + k * LEGEND_LINE;
        char attrs[80];
        fill_attrs(s[which[k]].colour, attrs, sizeof attrs);
        viz_rect(b, LEFT, y, 12, 12, attrs);
        viz_text(b, LEFT + 18, y + 10.5, 12, "start", 0, "#111111", legend[k]);
    }
    if (has_xc) {
        double y = TOP + nser * LEGEND_LINE;
        viz_rect(b, LEFT, y, 12, 12, band_attrs);
        viz_text(b, LEFT + 18, y + 10.5, 12, "start", 0, "#111111", legend[nser]);
    }
    if (whiskers[0])
        viz_text(b, w - RIGHT, 22, 11, "end", 0, "#555555", whiskers);
    /* Axis and grid, one per row, all at one scale. */
    double step, top = axis_top(e, n, &step);
    double ppu = PLOT_H / top;
    for (int r = 0; r < nrows; r++) {
        double y_top = TOP + legend_h + r * ROW_H, y0 = y_top + PLOT_H;
        double row_w = (r + 1 < nrows ? per_row : n - r * per_row) * group_w;
        for (int t = 0; t * step <= top + 1e-9; t++) {
            double y = y0 - t * step * ppu;
            viz_xy(b, "<path d=\"M", LEFT, y);
            viz_xy(b, " L", LEFT + row_w, y);
            vbuf_printf(b, "\" stroke=\"%s\" stroke-width=\"1\"/>\n", t ? "#e3e3e3" : "#111111");
            char lab[16];
            snprintf(lab, sizeof lab, "%g%%", 100.0 * t * step);
            viz_text(b, LEFT - 6, y + 4, 11, "end", 0, "#333333", lab);
        }
        vbuf_put(b, "<text x=\"14\" y=\"");
        vbuf_num(b, y_top + PLOT_H / 2.0);
        vbuf_put(b, "\" font-size=\"12\" text-anchor=\"middle\" fill=\"#333333\" transform=\"rotate(-90 14 ");
        vbuf_num(b, y_top + PLOT_H / 2.0);
        vbuf_put(b, ")\">probability</text>\n");
    }
    /* Thumbnails: every pose at one scale, like the gallery. */
    viz_view view;
    viz_view_default(&view);
    double ew, eh;
    viz_pic *pics = viz_pics_build(in, e, n, &view, &ew, &eh);
    double tscale = fmin((THUMB - 4.0) / ew, (THUMB - 4.0) / eh);
    for (int i = 0; i < n; i++) {
        double y0 = TOP + legend_h + (i / per_row) * ROW_H + PLOT_H;
        double gx = LEFT + (i % per_row) * group_w + GROUP_GAP / 2.0;
        double inner = nser * (BAR_W + BAR_GAP) - BAR_GAP;
        double bx = gx + (group_w - GROUP_GAP - inner) / 2.0;
        vbuf_printf(b, "<g class=\"group\"><title>Pose %d</title>\n", e[i].number);
        for (int k = 0; k < nser; k++) {
            double x = bx + k * (BAR_W + BAR_GAP), xc = x + BAR_W / 2.0;
            int wk = which[k];
            double v = wk == 0 ? e[i].p_qs : wk == 1 ? e[i].p_pqs : wk == 2 ? e[i].p : e[i].mp;
            bar(b, x, y0, v * ppu, s[wk].colour);
            if (wk == 2)
                whisker(b, xc, y0 - e[i].lo * ppu, y0 - e[i].hi * ppu);
            if (wk == 2 && e[i].has_xc)
                band(b, xc, y0 - e[i].x.lo * ppu, y0 - e[i].x.hi * ppu);
            if (wk == 3 && e[i].meas_ci)
                whisker(b, xc, y0 - e[i].mlo * ppu, y0 - e[i].mhi * ppu);
        }
        char lab[16];
        snprintf(lab, sizeof lab, "%d%s", e[i].number, has_xc && e[i].x.apart ? " !" : "");
        double cx = gx + (group_w - GROUP_GAP) / 2.0;
        viz_text(b, cx, y0 + 16, 12, "middle", 1, "#111111", lab);
        if (pics)
            viz_pic_draw(b, in->part, &pics[i], &view, tscale, cx, y0 + 22 + THUMB / 2.0, 0);
        vbuf_put(b, "</g>\n");
    }
    viz_text(b, LEFT + plot_w / 2.0, h - 4, 11, "middle", 0, "#555555", caption);
    vbuf_put(b, "</g>\n");
    viz_svg_close(b);
    int complete = pics != NULL;
    viz_pics_free(pics, n);
    free(e);
    if (!complete || b->failed)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    return PD_OK;
}
