/* draw.c: one pose drawn as SVG, and the SVG pieces every figure uses. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/vec3.h"
#include "viz/viz_const.h"
#include "viz/viz_internal.h"

void viz_svg_open(vbuf *b, int standalone, double w, double h, const char *title)
{
    if (standalone)
        vbuf_put(b, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    vbuf_put(b, "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"");
    vbuf_num(b, w);
    vbuf_put(b, "\" height=\"");
    vbuf_num(b, h);
    vbuf_put(b, "\" viewBox=\"0 0 ");
    vbuf_num(b, w);
    vbuf_put(b, " ");
    vbuf_num(b, h);
    vbuf_put(b, "\" font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n<title>");
    vbuf_escape(b, title);
    vbuf_put(b, "</title>\n");
    viz_rect(b, 0, 0, w, h, "fill=\"#ffffff\"");
}

void viz_svg_close(vbuf *b)
{
    vbuf_put(b, "</svg>\n");
}

void viz_text(vbuf *b, double x, double y, double size, const char *anchor, int bold,
              const char *fill, const char *text)
{
    vbuf_put(b, "<text x=\"");
    vbuf_num(b, x);
    vbuf_put(b, "\" y=\"");
    vbuf_num(b, y);
    vbuf_put(b, "\" font-size=\"");
    vbuf_num(b, size);
    vbuf_printf(b, "\" text-anchor=\"%s\"%s fill=\"%s\">", anchor,
                bold ? " font-weight=\"bold\"" : "", fill);
    vbuf_escape(b, text);
    vbuf_put(b, "</text>\n");
}

double viz_nice_length(double want, char *label, size_t size)
{
    double p10 = pow(10.0, floor(log10(want)));
    double m = want / p10;
    double len = (m >= 5.0 ? 5.0 : m >= 2.0 ? 2.0 : 1.0) * p10;
    if (len >= 1.0)
        snprintf(label, size, "%g m", len);
    else if (len >= 0.01)
        snprintf(label, size, "%g cm", len * 100.0);
    else
        snprintf(label, size, "%g mm", len * 1000.0);
    return len;
}

void viz_xy(vbuf *b, const char *lead, double x, double y)
{
    vbuf_put(b, lead);
    vbuf_num(b, x);
    vbuf_put(b, ",");
    vbuf_num(b, y);
}

void viz_rect(vbuf *b, double x, double y, double w, double h, const char *attrs)
{
    vbuf_put(b, "<rect x=\"");
    vbuf_num(b, x);
    vbuf_put(b, "\" y=\"");
    vbuf_num(b, y);
    vbuf_put(b, "\" width=\"");
    vbuf_num(b, w);
    vbuf_put(b, "\" height=\"");
    vbuf_num(b, h);
    vbuf_printf(b, "\" %s/>\n", attrs);
}

void viz_circle(vbuf *b, double x, double y, double r, const char *attrs)
{
    vbuf_put(b, "<circle cx=\"");
    vbuf_num(b, x);
    vbuf_put(b, "\" cy=\"");
    vbuf_num(b, y);
    vbuf_put(b, "\" r=\"");
    vbuf_num(b, r);
    vbuf_printf(b, "\" %s/>", attrs);
}

void viz_pic_free(viz_pic *pic)
{
    viz_scene_free(&pic->scene);
}

void viz_pics_free(viz_pic *pics, int n)
{
    for (int i = 0; pics && i < n; i++)
        viz_pic_free(&pics[i]);
    free(pics);
}

viz_pic *viz_pics_build(const viz_input *in, const viz_entry *e, int n, const viz_view *view,
                        double *w, double *h)
{
    viz_pic *pics = calloc((size_t)n + 1, sizeof *pics);
    *w = *h = 0.0;
    for (int i = 0; pics && i < n; i++) {
        if (!viz_pic_build(in->part, in->res, e[i].pose, view, &pics[i])) {
            viz_pics_free(pics, i);
            return NULL;
        }
        *w = fmax(*w, pics[i].hi.x - pics[i].lo.x);
        *h = fmax(*h, pics[i].hi.y - pics[i].lo.y);
    }
    return pics;
}

static void extend(viz_pic *pic, viz_pt p)
{
    if (p.x < pic->lo.x) pic->lo.x = p.x;
    if (p.y < pic->lo.y) pic->lo.y = p.y;
    if (p.x > pic->hi.x) pic->hi.x = p.x;
    if (p.y > pic->hi.y) pic->hi.y = p.y;
}

static pd_vec3 floor_corner(const viz_pic *pic, int k)
{
    return v3(k == 0 || k == 3 ? -pic->floor_x : pic->floor_x,
              k < 2 ? -pic->floor_y : pic->floor_y, 0.0);
}

int viz_pic_build(const pd_part *part, const pd_static_result *res, int pose,
                  const viz_view *view, viz_pic *pic)
{
    memset(pic, 0, sizeof *pic);
    const pd_hull *h = part->hull;
    int f = res->poses[pose].facet;
    pic->facet = f;
    viz_frame_of(part->com, h->normal[f], h->offset[f], &pic->frame);
    if (!viz_scene_build(part->mesh, &pic->frame, view, !part->closed, &pic->scene))
        return 0;
    /* The floor: the part's footprint seen from above, with a margin of a
     * tenth of the size, so that it reads as a floor and not as a plinth. */
    double margin = 0.1 * part->size;
    for (int i = 0; i < part->mesh->nverts; i++) {
        pd_vec3 w = pic->scene.world[i];
        pic->floor_x = fmax(pic->floor_x, fabs(w.x) + margin);
        pic->floor_y = fmax(pic->floor_y, fabs(w.y) + margin);
    }
    pic->lo = pic->hi = viz_project(view, pic->scene.world[0]);
    for (int i = 0; i < part->mesh->nverts; i++)
        extend(pic, viz_project(view, pic->scene.world[i]));
    for (int k = 0; k < 4; k++)
        extend(pic, viz_project(view, floor_corner(pic, k)));
    return 1;
}

/* SVG coordinates of a world point. */
typedef struct {
    const viz_view *view;
    double scale, ox, oy; /* svg = (o + scale x, o - scale y) */
} placing;

static void put_pt(vbuf *b, const char *lead, const placing *pl, pd_vec3 w)
{
    viz_pt p = viz_project(pl->view, w);
    viz_xy(b, lead, pl->ox + pl->scale * p.x, pl->oy - pl->scale * p.y);
}

static void shade_colour(double shade, char out[8])
{
    /* A light steel blue at full light. */
    static const double base[3] = {168.0, 196.0, 224.0};
    unsigned c[3];
    for (int k = 0; k < 3; k++) {
        double v = base[k] * shade;
        c[k] = (unsigned)(v < 0 ? 0 : v > 255 ? 255 : v + 0.5);
    }
    snprintf(out, 8, "#%02x%02x%02x", c[0], c[1], c[2]);
}

/* The resting facet's loop on the floor, as "x,y x,y ...". */
static void put_facet(vbuf *b, const pd_part *part, const viz_pic *pic, const placing *pl)
{
    const pd_hull *h = part->hull;
    for (int k = h->facet_start[pic->facet]; k < h->facet_start[pic->facet + 1]; k++) {
        pd_vec3 w = viz_frame_apply(&pic->frame, h->verts[h->facet_vert[k]]);
        w.z = 0.0; /* on the plane within round-off; drawn exactly on it */
        put_pt(b, k > h->facet_start[pic->facet] ? " " : "", pl, w);
    }
}

void viz_pic_draw(vbuf *b, const pd_part *part, const viz_pic *pic, const viz_view *view,
                  double scale, double cx, double cy, int marks)
{
    placing pl = {view, scale, cx - scale * 0.5 * (pic->lo.x + pic->hi.x),
                  cy + scale * 0.5 * (pic->lo.y + pic->hi.y)};
    const pd_mesh *mesh = part->mesh;
    vbuf_put(b, "<g stroke-linejoin=\"round\" stroke-linecap=\"round\">\n<polygon points=\"");
    for (int k = 0; k < 4; k++)
        put_pt(b, k ? " " : "", &pl, floor_corner(pic, k));
    vbuf_put(b, "\" fill=\"#ececec\" stroke=\"#9a9a9a\" stroke-width=\"0.8\"/>\n");
    if (marks) {
        vbuf_put(b, "<polygon class=\"rest\" points=\"");
        put_facet(b, part, pic, &pl);
        vbuf_put(b, "\" fill=\"#f3b0aa\" stroke=\"none\"/>\n");
    }
    for (int i = 0; i < pic->scene.nfaces; i++) {
        const viz_face *face = &pic->scene.faces[i];
        const int *t = mesh->tris[face->tri];
        char colour[8];
        shade_colour(face->shade, colour);
        vbuf_put(b, "<polygon points=\"");
        for (int k = 0; k < 3; k++)
            put_pt(b, k ? " " : "", &pl, pic->scene.world[t[k]]);
        /* A stroke of the fill's own colour closes the hairline seams that
         * anti-aliasing leaves between neighbouring triangles. */
        vbuf_printf(b, "\" fill=\"%s\" stroke=\"%s\" stroke-width=\"0.6\"/>\n", colour, colour);
        int started = 0;
        for (int k = 0; k < 3; k++) {
            if (!viz_scene_edge_drawn(&pic->scene, mesh, face->tri, k))
                continue;
            put_pt(b, started ? " M" : "<path d=\"M", &pl, pic->scene.world[t[k]]);
            put_pt(b, " L", &pl, pic->scene.world[t[(k + 1) % 3]]);
            started = 1;
        }
        if (started)
            vbuf_put(b, "\" fill=\"none\" stroke=\"#2b3640\" stroke-width=\"0.9\"/>\n");
    }
    if (marks) {
        /* The resting facet hidden under the part, dashed, and the centre of
         * mass with its plumb line to the floor: it falls inside the facet. */
        vbuf_put(b, "<polygon points=\"");
        put_facet(b, part, pic, &pl);
        vbuf_put(b, "\" fill=\"none\" stroke=\"#c0392b\" stroke-width=\"1.4\" "
                    "stroke-dasharray=\"4,3\"/>\n");
        pd_vec3 com = viz_frame_apply(&pic->frame, part->com);
        pd_vec3 foot = v3(com.x, com.y, 0.0);
        put_pt(b, "<path d=\"M", &pl, com);
        put_pt(b, " L", &pl, foot);
        vbuf_put(b, "\" fill=\"none\" stroke=\"#c0392b\" stroke-width=\"1\" stroke-dasharray=\"2,2\"/>\n");
        viz_pt c = viz_project(view, com);
        double x = pl.ox + scale * c.x, y = pl.oy - scale * c.y;
        vbuf_put(b, "<g class=\"com\">");
        viz_circle(b, x, y, 4.5, "fill=\"#ffffff\" stroke=\"#111111\" stroke-width=\"1.2\"");
        /* Two opposite quarters filled: the usual centre-of-mass sign. */
        for (int q = 0; q < 2; q++) {
            double s = q ? -4.5 : 4.5;
            viz_xy(b, q ? " M" : "<path d=\"M", x, y - s);
            viz_xy(b, " A4.5,4.5 0 0,1 ", x + s, y);
            viz_xy(b, " L", x, y);
            vbuf_put(b, " Z");
        }
        vbuf_put(b, "\" fill=\"#111111\"/></g>\n");
    }
    vbuf_put(b, "</g>\n");
}
