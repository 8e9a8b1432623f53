/* shapes.c: test fixtures (see shapes.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/gsl_adapter.h"
#include "posedrop/hull.h"
#include "posedrop/part.h"
#include "posedrop/sim.h"
#include "posedrop/static.h"
#include "posedrop/tolerances.h"
#include "shapes.h"
#include "base/vec3.h"

uint64_t rng_next(test_rng *r)
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

double rng_uniform(test_rng *r) { return (double)(rng_next(r) >> 11) * 0x1.0p-53; }

double rng_range(test_rng *r, double lo, double hi) { return lo + (hi - lo) * rng_uniform(r); }

pd_vec3 rng_unit_vector(test_rng *r)
{
    /* Archimedes: z uniform in [-1, 1] and a uniform azimuth is uniform on S^2. */
    double z = rng_range(r, -1.0, 1.0), phi = rng_range(r, 0.0, 2.0 * M_PI);
    double s = sqrt(fmax(0.0, 1.0 - z * z));
    return v3(s * cos(phi), s * sin(phi), z);
}

void rng_rotation(test_rng *r, double R[3][3])
{
    /* Uniform unit quaternion (Shoemake 1992). */
    double u1 = rng_uniform(r), u2 = 2.0 * M_PI * rng_uniform(r), u3 = 2.0 * M_PI * rng_uniform(r);
    double a = sqrt(1.0 - u1), b = sqrt(u1);
    double w = a * sin(u2), x = a * cos(u2), y = b * sin(u3), z = b * cos(u3);
    R[0][0] = 1 - 2 * (y * y + z * z); R[0][1] = 2 * (x * y - w * z);     R[0][2] = 2 * (x * z + w * y);
    R[1][0] = 2 * (x * y + w * z);     R[1][1] = 1 - 2 * (x * x + z * z); R[1][2] = 2 * (y * z - w * x);
    R[2][0] = 2 * (x * z - w * y);     R[2][1] = 2 * (y * z + w * x);     R[2][2] = 1 - 2 * (x * x + y * y);
}

pd_vec3 rot_apply(const double R[3][3], pd_vec3 v)
{
    return v3(R[0][0] * v.x + R[0][1] * v.y + R[0][2] * v.z,
              R[1][0] * v.x + R[1][1] * v.y + R[1][2] * v.z,
              R[2][0] * v.x + R[2][1] * v.y + R[2][2] * v.z);
}

void points_transform(pd_vec3 *p, int n, const double R[3][3], double scale, pd_vec3 t)
{
    for (int i = 0; i < n; i++)
        p[i] = v3_add(v3_scale(rot_apply(R, p[i]), scale), t);
}

void mesh_transform(pd_mesh *m, const double R[3][3], double scale, pd_vec3 t)
{
    points_transform(m->verts, m->nverts, R, scale, t);
}

/* --- brute-force hull ----------------------------------------------------- */

typedef struct { pd_vec3 n; double d; } plane;

/* All distinct supporting planes through three of the points. */
static int find_planes(const pd_vec3 *p, int n, plane **out)
{
    double size = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++)
            size = fmax(size, v3_dist(p[i], p[j]));
    double tol = 1e-9 * size;
    int cap = 64, np = 0;
    plane *pl = malloc(sizeof *pl * (size_t)cap);
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++)
            for (int k = j + 1; k < n; k++) {
                pd_vec3 nn = v3_cross(v3_sub(p[j], p[i]), v3_sub(p[k], p[i]));
                if (v3_norm(nn) <= 1e-9 * size * size)
                    continue;
                nn = v3_unit(nn);
                double d = v3_dot(nn, p[i]);
                int above = 0, below = 0;
                for (int m = 0; m < n; m++) {
                    double s = v3_dot(nn, p[m]) - d;
                    above += s > tol;
                    below += s < -tol;
                }
                if (above && below)
                    continue;
                if (above) {
                    nn = v3_neg(nn);
                    d = -d;
                }
                int dup = 0;
                for (int q = 0; q < np && !dup; q++)
                    dup = v3_dot(pl[q].n, nn) > 1.0 - 1e-12 && fabs(pl[q].d - d) <= tol;
                if (dup)
                    continue;
                if (np == cap)
                    pl = realloc(pl, sizeof *pl * (size_t)(cap *= 2));
                pl[np].n = nn;
                pl[np].d = d;
                np++;
            }
    *out = pl;
    return np;
}

int convex_facet_count(const pd_vec3 *pts, int n)
{
    plane *pl;
    int np = find_planes(pts, n, &pl);
    free(pl);
    return np;
}

typedef struct { double ang; int idx; } angle_idx;

static int cmp_angle(const void *a, const void *b)
{
    double x = ((const angle_idx *)a)->ang, y = ((const angle_idx *)b)->ang;
    return (x > y) - (x < y);
}

pd_mesh *convex_mesh(const pd_vec3 *pts, int n)
{
    plane *pl;
    int np = find_planes(pts, n, &pl);
    if (np < 4) {
        free(pl);
        return NULL;
    }
    double size = 0.0;
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++)
            size = fmax(size, v3_dist(pts[i], pts[j]));
    pd_mesh *m = calloc(1, sizeof *m);
    m->verts = malloc(sizeof *m->verts * (size_t)n);
    memcpy(m->verts, pts, sizeof *m->verts * (size_t)n);
    m->nverts = n;
    int cap = 3 * n + 16;
    m->tris = malloc(sizeof *m->tris * (size_t)cap);
    angle_idx *loop = malloc(sizeof *loop * (size_t)n);
    for (int f = 0; f < np; f++) {
        int k = 0;
        pd_vec3 c = v3(0, 0, 0);
        for (int i = 0; i < n; i++)
            if (fabs(v3_dot(pl[f].n, pts[i]) - pl[f].d) <= 1e-9 * size) {
                loop[k++].idx = i;
                c = v3_add(c, pts[i]);
            }
        c = v3_scale(c, 1.0 / k);
        pd_vec3 u = v3_unit(v3_sub(pts[loop[0].idx], c)), w = v3_cross(pl[f].n, u);
        for (int i = 0; i < k; i++) {
            pd_vec3 d = v3_sub(pts[loop[i].idx], c);
            loop[i].ang = atan2(v3_dot(d, w), v3_dot(d, u));
        }
        qsort(loop, (size_t)k, sizeof *loop, cmp_angle);
        /* Fan from the centroid would add a vertex; fan from the first corner
         * instead is exact for a convex loop (points on edges give zero-area
         * triangles only if collinear with the apex, which a loop start avoids
         * when it is a corner: start from the point farthest from c). */
        int start = 0;
        double best = -1.0;
        for (int i = 0; i < k; i++) {
            double dd = v3_dist(pts[loop[i].idx], c);
            if (dd > best) {
                best = dd;
                start = i;
            }
        }
        for (int i = 1; i + 1 < k; i++) {
            if (m->ntris == cap)
                m->tris = realloc(m->tris, sizeof *m->tris * (size_t)(cap *= 2));
            m->tris[m->ntris][0] = loop[start].idx;
            m->tris[m->ntris][1] = loop[(start + i) % k].idx;
            m->tris[m->ntris][2] = loop[(start + i + 1) % k].idx;
            m->ntris++;
        }
    }
    free(loop);
    free(pl);
    return m;
}

/* --- standard solids -------------------------------------------------------- */

int pts_box(double ax, double ay, double az, pd_vec3 *out)
{
    for (int i = 0; i < 8; i++)
        out[i] = v3((i & 1 ? 0.5 : -0.5) * ax, (i & 2 ? 0.5 : -0.5) * ay, (i & 4 ? 0.5 : -0.5) * az);
    return 8;
}

int pts_prism(int nsides, double radius, double height, pd_vec3 *out)
{
    for (int i = 0; i < nsides; i++) {
        double t = 2.0 * M_PI * i / nsides;
        out[i] = v3(radius * cos(t), radius * sin(t), -0.5 * height);
        out[nsides + i] = v3(radius * cos(t), radius * sin(t), 0.5 * height);
    }
    return 2 * nsides;
}

int pts_flat_pyramid(int nsides, double height, pd_vec3 *out)
{
    for (int i = 0; i < nsides; i++) {
        double t = 2.0 * M_PI * i / nsides;
        out[i] = v3(cos(t), sin(t), 0.0);
    }
    out[nsides] = v3(0.0, 0.0, height);
    return nsides + 1;
}

int pts_parallelogram_prism(pd_vec3 *out)
{
    const double xz[4][2] = {{0, 0}, {1, 0}, {2, 1}, {1, 1}};
    for (int i = 0; i < 4; i++) {
        out[i] = v3(xz[i][0], 0, xz[i][1]);
        out[4 + i] = v3(xz[i][0], 1, xz[i][1]);
    }
    return 8;
}

int pts_tetrahedron(pd_vec3 *out)
{
    out[0] = v3(1, 1, 1);
    out[1] = v3(1, -1, -1);
    out[2] = v3(-1, 1, -1);
    out[3] = v3(-1, -1, 1);
    return 4;
}

int pts_cube(pd_vec3 *out) { return pts_box(2, 2, 2, out); }

int pts_octahedron(pd_vec3 *out)
{
    for (int i = 0; i < 3; i++) {
        double a[3] = {0, 0, 0};
        a[i] = 1;
        out[2 * i] = v3(a[0], a[1], a[2]);
        out[2 * i + 1] = v3(-a[0], -a[1], -a[2]);
    }
    return 6;
}

int pts_icosahedron(pd_vec3 *out)
{
    double g = (1.0 + sqrt(5.0)) / 2.0;
    int k = 0;
    for (int s1 = -1; s1 <= 1; s1 += 2)
        for (int s2 = -1; s2 <= 1; s2 += 2) {
            out[k++] = v3(0, s1, s2 * g);
            out[k++] = v3(s1, s2 * g, 0);
            out[k++] = v3(s2 * g, 0, s1);
        }
    return k;
}

int pts_dodecahedron(pd_vec3 *out)
{
    double g = (1.0 + sqrt(5.0)) / 2.0, h = 1.0 / g;
    int k = 0;
    for (int i = 0; i < 8; i++)
        out[k++] = v3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1);
    for (int s1 = -1; s1 <= 1; s1 += 2)
        for (int s2 = -1; s2 <= 1; s2 += 2) {
            out[k++] = v3(0, s1 * h, s2 * g);
            out[k++] = v3(s1 * h, s2 * g, 0);
            out[k++] = v3(s2 * g, 0, s1 * h);
        }
    return k;
}

pd_mesh *mesh_box(double ax, double ay, double az)
{
    pd_vec3 p[8];
    return convex_mesh(p, pts_box(ax, ay, az, p));
}

pd_mesh *mesh_prism(int nsides, double radius, double height)
{
    pd_vec3 p[64];
    return convex_mesh(p, pts_prism(nsides, radius, height, p));
}

pd_mesh *mesh_roof_box(double w, double d, double h, double ridge)
{
    double rise = 0.5 * w * tan(0.5 * ridge);
    pd_vec3 p[10];
    int n = 0;
    for (int sy = -1; sy <= 1; sy += 2) {
        p[n++] = v3(0.0, 0.5 * sy * d, 0.0);
        for (int sx = -1; sx <= 1; sx += 2) {
            p[n++] = v3(0.5 * sx * w, 0.5 * sy * d, rise);
            p[n++] = v3(0.5 * sx * w, 0.5 * sy * d, h);
        }
    }
    return convex_mesh(p, n);
}

pd_mesh *mesh_of_hull(const pd_hull *h)
{
    pd_mesh *m = calloc(1, sizeof *m);
    m->nverts = h->nverts;
    m->verts = malloc(sizeof *m->verts * (size_t)h->nverts);
    memcpy(m->verts, h->verts, sizeof *m->verts * (size_t)h->nverts);
    int nt = 0;
    for (int f = 0; f < h->nfacets; f++)
        nt += h->facet_start[f + 1] - h->facet_start[f] - 2;
    m->tris = malloc(sizeof *m->tris * (size_t)nt);
    for (int f = 0; f < h->nfacets; f++) {
        const int *loop = h->facet_vert + h->facet_start[f];
        int k = h->facet_start[f + 1] - h->facet_start[f];
        for (int i = 1; i + 1 < k; i++) {
            m->tris[m->ntris][0] = loop[0];
            m->tris[m->ntris][1] = loop[i];
            m->tris[m->ntris][2] = loop[i + 1];
            m->ntris++;
        }
    }
    return m;
}

double uniform_p_value(const pd_sim_result *r)
{
    long settled = 0;
    for (int k = 0; k < r->nposes; k++)
        settled += r->count[k];
    double expect = (double)settled / r->nposes, x2 = 0.0;
    for (int k = 0; k < r->nposes; k++)
        x2 += (r->count[k] - expect) * (r->count[k] - expect) / expect;
    return pd_gsl_chisq_q(x2, r->nposes - 1);
}

pd_part *part_of(pd_mesh *m, const pd_vec3 *com, pd_diag *diag)
{
    pd_part_options po;
    pd_part_options_default(&po);
    if (com) {
        po.com_given = 1;
        po.com = *com;
    }
    pd_part *part = NULL;
    pd_status st = m ? pd_part_build(m, &po, &part, diag) : PD_ERR_INTERNAL;
    pd_mesh_free(m);
    if (st != PD_OK)
        printf("     part_of: %s (%s)\n", pd_status_str(st), diag ? diag->message : "");
    return st == PD_OK ? part : NULL;
}

pd_status part_of_points(const pd_vec3 *pts, int n, pd_part **part, pd_diag *diag)
{
    pd_hull *h = NULL;
    *part = NULL;
    pd_status st = pd_hull_build(pts, n, &h, diag);
    if (st == PD_OK) {
        pd_mesh *m = mesh_of_hull(h);
        st = m ? pd_part_build(m, NULL, part, diag) : PD_ERR_NOMEM;
        pd_mesh_free(m);
    }
    pd_hull_free(h);
    return st;
}

pd_part *part_random_ellipsoid(test_rng *rng, int n, double ay, double az, double cx, double cy)
{
    pd_vec3 pts[64];
    if (n > 64)
        n = 64;
    for (int i = 0; i < n; i++) {
        pd_vec3 u = rng_unit_vector(rng);
        pts[i] = v3(u.x, ay * u.y, az * u.z);
    }
    pd_vec3 com = v3(rng_range(rng, -cx, cx), rng_range(rng, -cy, cy), 0.0);
    return part_of(convex_mesh(pts, n), &com, NULL);
}

/* x rounded to float. Through a volatile: GCC 12.2 at -O2 compiles
 * v3((float)x, (float)y, (float)z) into one conversion, of z, and leaves x
 * and y unrounded (its SLP vectorizer; -fno-tree-slp-vectorize or -O1 do
 * not). */
static double to_float32(double x)
{
    volatile float f = (float)x;
    return f;
}

/* Rings: see shapes.h. */
pd_vec3 *ring_points(const ring_spec *r, test_rng *rng, int *n)
{
    int per = r->pair > 0.0 ? 2 : 1, rings = r->pyramid ? 1 : 2;
    pd_vec3 *p = malloc(sizeof *p * (size_t)(per * rings * r->nsides + 1));
    int m = 0;
    for (int i = 0; i < r->nsides; i++)
        for (int k = 0; k < per; k++) {
            double t = 2.0 * M_PI * i / r->nsides + k * r->pair;
            p[m++] = v3(cos(t), sin(t), -0.5);
            if (!r->pyramid)
                p[m++] = v3(cos(t + r->twist), sin(t + r->twist), 0.5);
        }
    if (r->pyramid)
        p[m++] = v3(0.0, 0.0, 1.0);
    double size = sqrt(r->pyramid ? 8.0 + 2.25 : 9.0); /* bounding-box diagonal */
    for (int i = 0; i < m; i++) {
        double s = r->noise * PD_TOL_SYMMETRY_REL * size * rng_uniform(rng);
        p[i] = v3_add(p[i], v3_scale(rng_unit_vector(rng), s));
        /* A part of 12 mm placed at (37, -21, 5) mm, in mm. */
        pd_vec3 q = v3_add(v3_scale(p[i], 6.15), v3(37.0, -21.0, 5.0));
        if (r->float32)
            q = v3(to_float32(q.x), to_float32(q.y), to_float32(q.z));
        if (r->digits) {
            char buf[64];
            snprintf(buf, sizeof buf, "%.*g %.*g %.*g", r->digits, q.x, r->digits, q.y,
                     r->digits, q.z);
            if (sscanf(buf, "%lf %lf %lf", &q.x, &q.y, &q.z) != 3)
                q = v3(NAN, NAN, NAN);
        }
        if (r->float32 || r->digits)
            p[i] = q;
    }
    *n = m;
    return p;
}

pd_part *ring_part(const ring_spec *r, const double R[3][3], double scale, pd_vec3 t)
{
    test_rng rng = {99};
    int n;
    pd_vec3 *pts = ring_points(r, &rng, &n);
    if (R)
        points_transform(pts, n, R, scale, t);
    pd_hull *h = NULL;
    pd_part *part = NULL;
    if (pd_hull_build(pts, n, &h, NULL) == PD_OK)
        part = part_of(mesh_of_hull(h), NULL, NULL);
    pd_hull_free(h);
    free(pts);
    return part;
}

int mesh_part(pd_mesh *m, pd_part **part, pd_static_result **poses)
{
    *part = NULL;
    *poses = NULL;
    int ok = m && pd_part_build(m, NULL, part, NULL) == PD_OK &&
             pd_static_estimate(*part, NULL, poses, NULL) == PD_OK;
    pd_mesh_free(m);
    if (!ok) {
        pd_static_result_free(*poses);
        pd_part_free(*part);
        *part = NULL;
        *poses = NULL;
    }
    return ok;
}
