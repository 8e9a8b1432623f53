/* viz_internal.h: what the gallery, chart, sphere and report share. */
#ifndef PD_VIZ_INTERNAL_H
#define PD_VIZ_INTERNAL_H

#include "viz/project.h"
#include "viz/vbuf.h"
#include "viz/viz.h"

/* One row of the CSV: a pose, or a class of poses. */
typedef struct viz_entry {
    int number;        /* 1-based, the CSV's pose column */
    int pose;          /* the pose drawn: the class's first member */
    int members;       /* poses in the class (1 without --group) */
    double p_qs, p_pqs;
    int has_dyn;
    double p, lo, hi;  /* dynamic estimate and its 95% interval */
    int has_meas, meas_ci;
    double mp, mlo, mhi;
    int has_xc;        /* --crosscheck: the engines' spread below */
    viz_spread x;
} viz_entry;

/* The entries of in (caller frees *out). PD_ERR_USAGE when the measured
 * distribution names a pose beyond them, PD_ERR_NOMEM. */
pd_status viz_entries(const viz_input *in, viz_entry **out, int *n, pd_diag *diag);

/* eq. (16) of the paper, 100 sum_i m_i |a_i - m_i| with m the measured and a
 * the estimated distribution, and the total variation 50 sum_i |a_i - m_i|,
 * both in percent, over the entries (which hold every measured pose). which:
 * 0 QS, 1 PQS, 2 dynamic. */
void viz_eq16(const viz_entry *e, int n, int which, double *e16, double *tv);

/* "uniform", "bootstrap" or "stationary". */
const char *viz_initial_name(pd_initial initial);

/* The file name without its folders, for titles ("the part" for NULL). */
const char *viz_base_name(const char *path);

/* The colour of entry i of n (the sphere's regions, the gallery's swatches). */
void viz_entry_colour(int i, char out[8]);

/* A pose laid out for drawing at some scale: the mesh in the pose's frame
 * in painter's order, with the extent of everything the panel shows. */
typedef struct viz_pic {
    viz_scene scene;
    viz_frame frame;
    int facet;
    double floor_x, floor_y;   /* half sides of the floor drawn, world */
    viz_pt lo, hi;             /* projected extent (view units, y up) */
} viz_pic;

int viz_pic_build(const pd_part *part, const pd_static_result *res, int pose,
                  const viz_view *view, viz_pic *pic);
void viz_pic_free(viz_pic *pic);
/* Draws pic scaled by scale (px per m) with its extent's centre at (cx, cy)
 * in SVG coordinates. marks: the resting facet and the centre of mass too. */
void viz_pic_draw(vbuf *b, const pd_part *part, const viz_pic *pic, const viz_view *view,
                  double scale, double cx, double cy, int marks);

/* lead, then "x,y" (a path command and its point, or a separator). */
void viz_xy(vbuf *b, const char *lead, double x, double y);

/* A rectangle at (x, y) of w by h, then the rest of its attributes (fill,
 * stroke), closed. */
void viz_rect(vbuf *b, double x, double y, double w, double h, const char *attrs);
/* A circle at (x, y) of radius r, then the rest of its attributes, closed. */
void viz_circle(vbuf *b, double x, double y, double r, const char *attrs);

/* Every entry's pose laid out (NULL when out of memory), with the largest
 * extent among them, which sets the common scale. */
viz_pic *viz_pics_build(const viz_input *in, const viz_entry *e, int n, const viz_view *view,
                        double *w, double *h);
void viz_pics_free(viz_pic *pics, int n);

/* <svg ...> with the SVG 1.1 namespace and version; standalone files get the
 * XML declaration first. */
void viz_svg_open(vbuf *b, int standalone, double w, double h, const char *title);
void viz_svg_close(vbuf *b);
/* The width in px of text (UTF-8) set at size px in DejaVu Sans (bold when
 * bold): the sum of its characters' advances (text_width.c). */
double viz_text_width(const char *text, double size, int bold);
/* The vertical extent of a line of that font's ASCII text about its
 * baseline, in em: every printable ASCII glyph of both weights lies within
 * 0.80 above ('`' the highest) and 0.236 below ('_', 'g', 'p') by the fonts'
 * glyph bounding boxes. */
#define VIZ_TEXT_ASCENT 0.80
#define VIZ_TEXT_DESCENT 0.24
/* <text> at (x, y) with the given size, anchor and weight, text escaped. */
void viz_text(vbuf *b, double x, double y, double size, const char *anchor, int bold,
              const char *fill, const char *text);

/* A round length near want (1, 2 or 5 times a power of ten) and its label
 * in mm, cm or m. */
double viz_nice_length(double want, char *label, size_t size);

/* The region of the gauss-sphere map that hull facet f covers: the gravity
 * directions (from the centre of mass) whose ray meets the facet, a
 * spherical polygon bounded by great-circle arcs, cut to the hemisphere
 * side * z >= 0 of the part's frame and projected orthographically on the
 * unit disc, as seen from side * z (seen from below, x is mirrored). Arcs are
 * sampled every VIZ_ARC_STEP_DEG at most. Returns the number of points
 * written to *pts (caller frees), 0 when the region misses the hemisphere,
 * -1 when out of memory. */
int viz_sphere_region(const pd_part *part, int f, int side, viz_pt **pts);

/* The three figures, as <svg> elements (standalone: a file of their own). */
pd_status viz_gallery(const viz_input *in, int standalone, vbuf *b, pd_diag *diag);
pd_status viz_chart(const viz_input *in, int standalone, vbuf *b, pd_diag *diag);
pd_status viz_sphere(const viz_input *in, int standalone, vbuf *b, pd_diag *diag);
pd_status viz_report(const viz_input *in, const viz_run *run, vbuf *b, pd_diag *diag);
/* in->sensitivity as a chart, and in words (a list) for the report. */
pd_status viz_sensitivity(const viz_input *in, int standalone, vbuf *b, pd_diag *diag);
void viz_sensitivity_words(vbuf *b, const viz_input *in);

#endif
