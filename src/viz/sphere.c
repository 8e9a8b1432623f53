/* sphere.c: the gauss-sphere map. Every direction of gravity in the part's
 * frame, coloured by the stable pose the quasi-static descent takes the part
 * to from the facet that direction meets; the facets' regions outlined; the
 * sphere as two orthographic hemispheres, z >= 0 seen from above and z <= 0
 * from below. The coloured share of the sphere is each pose's QS
 * probability (a region's solid angle over 4 pi). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/vec3.h"
#include "viz/viz_const.h"
#include "viz/viz_internal.h"

enum { RADIUS = 150, MARGIN = 20, TOP = 44, LEGEND_W = 150 };

typedef struct {
    pd_vec3 *p;
    unsigned char *exit; /* 1: the polygon leaves the hemisphere here */
    int n, cap;
    int failed;
} poly;

static void push(poly *pl, pd_vec3 p, int is_exit)
{
    if (pl->failed)
        return;
    if (pl->n == pl->cap) {
        int cap = pl->cap ? 2 * pl->cap : 64;
        pd_vec3 *np = realloc(pl->p, (size_t)cap * sizeof *np);
        unsigned char *ne = np ? realloc(pl->exit, (size_t)cap) : NULL;
        if (np)
            pl->p = np;
        if (!np || !ne) {
            pl->failed = 1;
            return;
        }
        pl->exit = ne;
        pl->cap = cap;
    }
    pl->exit[pl->n] = (unsigned char)is_exit;
    pl->p[pl->n++] = p;
}

/* Points of the great-circle arc from a to b (unit vectors less than 180
 * deg apart), b excluded, at most VIZ_ARC_STEP_DEG apart. */
static void arc(poly *pl, pd_vec3 a, pd_vec3 b)
{
    double theta = v3_angle(a, b);
    int m = (int)ceil(theta / (VIZ_ARC_STEP_DEG * (M_PI / 180.0)));
    if (m < 1)
        m = 1;
    double s = sin(theta);
    for (int k = 0; k < m; k++) {
        double t = (double)k / m;
        pd_vec3 p = a;
        if (k > 0 && s > 1e-12)
            p = v3_add(v3_scale(a, sin((1.0 - t) * theta) / s), v3_scale(b, sin(t * theta) / s));
        else if (k > 0)
            p = v3_unit(v3_lerp(a, b, t));
        push(pl, p, 0);
    }
}

int viz_sphere_region(const pd_part *part, int f, int side, viz_pt **pts)
{
    const pd_hull *h = part->hull;
    int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
    poly ring = {0}, cut = {0}, out = {0};
    for (int k = k0; k < k1; k++) {
        pd_vec3 a = v3_unit(v3_sub(h->verts[h->facet_vert[k]], part->com));
        pd_vec3 b = v3_unit(v3_sub(h->verts[h->facet_vert[k + 1 < k1 ? k + 1 : k0]], part->com));
        arc(&ring, a, b);
    }
    /* Cut to side * z >= 0 (Sutherland-Hodgman in 3-D; the cut points lie on
     * the equator), marking where the polygon leaves the hemisphere. */
    for (int i = 0; i < ring.n && !ring.failed; i++) {
        pd_vec3 s = ring.p[(i + ring.n - 1) % ring.n], e = ring.p[i];
        double zs = side * s.z, ze = side * e.z;
        if ((zs >= 0) != (ze >= 0)) {
            pd_vec3 c = v3_lerp(s, e, zs / (zs - ze));
            c.z = 0.0;
            push(&cut, v3_unit(c), zs >= 0);
        }
        if (ze >= 0)
            push(&cut, e, 0);
    }
    /* Where it left and came back, the boundary runs along the equator: the
     * shorter way, since a facet's region lies within an open hemisphere. */
    for (int i = 0; i < cut.n && !cut.failed; i++) {
        if (cut.exit[i])
            arc(&out, cut.p[i], cut.p[(i + 1) % cut.n]);
        else
            push(&out, cut.p[i], 0);
    }
    int n = ring.failed || cut.failed || out.failed ? -1 : out.n;
    *pts = NULL;
    if (n > 0) {
        *pts = malloc((size_t)n * sizeof **pts);
        if (!*pts)
            n = -1;
        for (int i = 0; i < n; i++) {
            viz_pt q = {side > 0 ? out.p[i].x : -out.p[i].x, out.p[i].y};
            (*pts)[i] = q;
        }
    }
    free(ring.p);
    free(ring.exit);
    free(cut.p);
    free(cut.exit);
    free(out.p);
    free(out.exit);
    return n;
}

/* The arcs where one pose's region meets another's, cut to the hemisphere,
 * as path segments: the basins' borders, drawn over the facets' outlines. */
static void basin_borders(vbuf *b, const pd_part *part, const int *entry_of_facet, int side,
                          double cx, double cy)
{
    const pd_hull *h = part->hull;
    int started = 0;
    for (int f = 0; f < h->nfacets; f++) {
        int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
        for (int k = k0; k < k1; k++) {
            int g = h->facet_adj[k];
            if (g < f || entry_of_facet[g] == entry_of_facet[f])
                continue;
            poly pl = {0};
            pd_vec3 a = v3_unit(v3_sub(h->verts[h->facet_vert[k]], part->com));
            pd_vec3 e = v3_unit(v3_sub(h->verts[h->facet_vert[k + 1 < k1 ? k + 1 : k0]], part->com));
            arc(&pl, a, e);
            push(&pl, e, 0);
            for (int i = 0; i + 1 < pl.n && !pl.failed; i++) {
                pd_vec3 p = pl.p[i], q = pl.p[i + 1];
                double zp = side * p.z, zq = side * q.z;
                if (zp < 0 && zq < 0)
                    continue;
                if (zp < 0 || zq < 0) {
                    pd_vec3 c = v3_lerp(p, q, zp / (zp - zq));
                    c.z = 0.0;
                    c = v3_unit(c);
                    if (zp < 0)
                        p = c;
                    else
                        q = c;
                }
                viz_xy(b, started ? " M" : "<path d=\"M", cx + RADIUS * (side > 0 ? p.x : -p.x),
                       cy - RADIUS * p.y);
                viz_xy(b, " L", cx + RADIUS * (side > 0 ? q.x : -q.x), cy - RADIUS * q.y);
                started = 1;
            }
            if (pl.failed)
                b->failed = 1;
            free(pl.p);
            free(pl.exit);
        }
    }
    if (started)
        vbuf_put(b, "\" fill=\"none\" stroke=\"#1a1a1a\" stroke-width=\"1.1\"/>\n");
}

static void disc_pt(vbuf *b, const char *lead, double cx, double cy, viz_pt p)
{
    viz_xy(b, lead, cx + RADIUS * p.x, cy - RADIUS * p.y);
}

pd_status viz_sphere(const viz_input *in, int standalone, vbuf *b, pd_diag *diag)
{
    viz_entry *e;
    int n;
    pd_status st = viz_entries(in, &e, &n, diag);
    if (st != PD_OK)
        return st;
    const pd_part *part = in->part;
    const pd_static_result *res = in->res;
    /* Each facet's colour: that of the entry its quasi-static rest belongs to. */
    int *entry_of_facet = malloc((size_t)res->nfacets * sizeof *entry_of_facet + 1);
    if (!entry_of_facet) {
        free(e);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    }
    for (int f = 0; f < res->nfacets; f++)
        entry_of_facet[f] = -1;
    for (int i = 0; i < res->nposes; i++)
        entry_of_facet[res->poses[i].facet] = in->class_of ? in->class_of[i] : i;
    for (int f = 0; f < res->nfacets; f++) {
        int r = res->facets[f].rest;
        entry_of_facet[f] = r >= 0 && r < res->nfacets ? entry_of_facet[r] : -1;
    }
    int legend_rows = n;
    double w = 2 * (2 * RADIUS + 2 * MARGIN) + LEGEND_W;
    double h = TOP + 2 * RADIUS + 2 * MARGIN + 34;
    double rows_h = TOP + 16.0 * legend_rows + 20;
    if (rows_h > h)
        h = rows_h;
    char title[512];
    snprintf(title, sizeof title, "Gauss-sphere map of %s: where quasi-static descent ends",
             viz_base_name(in->name));
    static const char *const subtitle =
        "Gravity's directions in the part's frame, coloured by the pose reached; dark lines: "
        "basin borders; thin: hull facets; dots: the poses.";
    /* Wider than the discs and legend when a long file name needs it. */
    w = ceil(fmax(w, 10 + fmax(viz_text_width(title, 16, 1), viz_text_width(subtitle, 11, 0)) + 10));
    viz_svg_open(b, standalone, w, h, title);
    vbuf_put(b, "<g class=\"sphere\">\n");
    viz_text(b, 10, 22, 16, "start", 1, "#111111", title);
    viz_text(b, 10, 38, 11, "start", 0, "#555555", subtitle);
    for (int hemi = 0; hemi < 2 && !b->failed; hemi++) {
        int side = hemi == 0 ? 1 : -1;
        double cx = MARGIN + RADIUS + hemi * (2 * RADIUS + 2 * MARGIN), cy = TOP + MARGIN + RADIUS;
        vbuf_printf(b, "<g class=\"hemisphere\"><title>%s</title>\n",
                    side > 0 ? "z &gt;= 0 seen from +z" : "z &lt;= 0 seen from -z");
        for (int f = 0; f < res->nfacets; f++) {
            viz_pt *pts;
            int np = viz_sphere_region(part, f, side, &pts);
            if (np < 0) {
                b->failed = 1;
                break;
            }
            if (np < 3) {
                free(pts);
                continue;
            }
            char colour[8] = "#ffffff";
            if (entry_of_facet[f] >= 0)
                viz_entry_colour(entry_of_facet[f], colour);
            vbuf_put(b, "<polygon points=\"");
            for (int i = 0; i < np; i++)
                disc_pt(b, i ? " " : "", cx, cy, pts[i]);
            vbuf_printf(b, "\" fill=\"%s\" stroke=\"#ffffff\" stroke-width=\"0.5\"/>\n", colour);
            free(pts);
        }
        basin_borders(b, part, entry_of_facet, side, cx, cy);
        viz_circle(b, cx, cy, RADIUS, "fill=\"none\" stroke=\"#111111\" stroke-width=\"1.2\"");
        /* The poses' own directions: each stable facet's normal. */
        for (int i = 0; i < res->nposes; i++) {
            pd_vec3 nrm = res->poses[i].normal;
            if (side * nrm.z < 0.0)
                continue;
            viz_pt p = {side > 0 ? nrm.x : -nrm.x, nrm.y};
            viz_circle(b, cx + RADIUS * p.x, cy - RADIUS * p.y, 2.5, "fill=\"#111111\"");
        }
        char lab[64];
        snprintf(lab, sizeof lab, "%s hemisphere (z %s 0), seen from %sz",
                 side > 0 ? "upper" : "lower", side > 0 ? ">=" : "<=", side > 0 ? "+" : "-");
        viz_text(b, cx, cy + RADIUS + 18, 12, "middle", 0, "#111111", lab);
        /* Axes of the part's frame at the disc's corner (x mirrored below). */
        double ox = cx - RADIUS + (side < 0 ? 24 : 0), oy = cy - RADIUS + 28;
        viz_xy(b, "<path d=\"M", ox + side * 24, oy);
        viz_xy(b, " L", ox, oy);
        viz_xy(b, " L", ox, oy - 24);
        vbuf_put(b, "\" fill=\"none\" stroke=\"#555555\" stroke-width=\"1\"/>\n");
        viz_text(b, ox + side * 30, oy + 4, 10, "middle", 0, "#555555", "x");
        viz_text(b, ox, oy - 28, 10, "middle", 0, "#555555", "y");
        vbuf_put(b, "</g>\n");
    }
    double lx = 4 * RADIUS + 4 * MARGIN + 8;
    for (int i = 0; i < n; i++) {
        char colour[8], lab[96];
        viz_entry_colour(i, colour);
        double y = TOP + MARGIN + 16.0 * i;
        snprintf(lab, sizeof lab, "fill=\"%s\"", colour);
        viz_rect(b, lx, y, 12, 12, lab);
        snprintf(lab, sizeof lab, "pose %d: QS %.1f%%", e[i].number, 100.0 * e[i].p_qs);
        viz_text(b, lx + 17, y + 10.5, 11.5, "start", 0, "#111111", lab);
    }
    vbuf_put(b, "</g>\n");
    viz_svg_close(b);
    free(entry_of_facet);
    free(e);
    return b->failed ? pd_fail(diag, PD_ERR_NOMEM, "out of memory") : PD_OK;
}
