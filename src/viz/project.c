/* project.c: the frame, view, culling and painter's order (see project.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/vec3.h"
#include "viz/project.h"
#include "viz/viz_const.h"

void viz_view_oblique(double az, double el, viz_view *view)
{
    view->toward = v3(cos(el) * cos(az), cos(el) * sin(az), sin(el));
    view->right = v3(-sin(az), cos(az), 0.0);
    view->up = v3_cross(view->toward, view->right);
    /* Up and to the left of the eye, a little toward it. */
    view->light = v3_unit(v3_add(v3_add(v3_scale(view->right, -0.45), v3_scale(view->up, 0.75)),
                                 v3_scale(view->toward, 0.5)));
}

void viz_view_default(viz_view *view)
{
    viz_view_oblique(VIZ_VIEW_AZ_DEG * (M_PI / 180.0), VIZ_VIEW_EL_DEG * (M_PI / 180.0), view);
}

void viz_frame_of(pd_vec3 com, pd_vec3 normal, double offset, viz_frame *f)
{
    pd_vec3 n = v3_unit(normal);
    pd_vec3 axes[3] = {v3(1, 0, 0), v3(0, 1, 0), v3(0, 0, 1)};
    int best = 0;
    for (int k = 1; k < 3; k++)
        if (fabs(v3_dot(axes[k], n)) < fabs(v3_dot(axes[best], n)))
            best = k;
    pd_vec3 z = v3_neg(n);
    pd_vec3 x = v3_unit(v3_sub(axes[best], v3_scale(z, v3_dot(axes[best], z))));
    f->row[0] = x;
    f->row[1] = v3_cross(z, x);
    f->row[2] = z;
    f->foot = v3_add(com, v3_scale(n, offset - v3_dot(n, com)));
}

pd_vec3 viz_frame_rotate(const viz_frame *f, pd_vec3 v)
{
    return v3(v3_dot(f->row[0], v), v3_dot(f->row[1], v), v3_dot(f->row[2], v));
}

pd_vec3 viz_frame_apply(const viz_frame *f, pd_vec3 x)
{
    return viz_frame_rotate(f, v3_sub(x, f->foot));
}

viz_pt viz_project(const viz_view *view, pd_vec3 world)
{
    viz_pt p = {v3_dot(world, view->right), v3_dot(world, view->up)};
    return p;
}

double viz_depth(const viz_view *view, pd_vec3 world)
{
    return v3_dot(world, view->toward);
}

void viz_scene_free(viz_scene *scene)
{
    free(scene->faces);
    free(scene->world);
    free(scene->rank);
    free(scene->across);
    memset(scene, 0, sizeof *scene);
}

/* Far to near; equal depths by triangle index, so the order (and the file)
 * does not depend on the sort's algorithm. */
static int by_depth(const void *pa, const void *pb)
{
    const viz_face *a = pa, *b = pb;
    if (a->depth != b->depth)
        return a->depth < b->depth ? -1 : 1;
    return (a->tri > b->tri) - (a->tri < b->tri);
}

typedef struct {
    int lo, hi, slot; /* slot = 3 t + k */
} edge_key;

static int by_edge(const void *pa, const void *pb)
{
    const edge_key *a = pa, *b = pb;
    if (a->lo != b->lo)
        return a->lo < b->lo ? -1 : 1;
    if (a->hi != b->hi)
        return a->hi < b->hi ? -1 : 1;
    return (a->slot > b->slot) - (a->slot < b->slot);
}

/* The triangle across each edge: edges sorted by their vertex pair; a pair
 * shared by exactly two triangles links them (more, on a non-manifold edge,
 * or one, on a boundary: none, and the edge is drawn as an outline). */
static int link_edges(const pd_mesh *mesh, int *across)
{
    size_t n = (size_t)mesh->ntris * 3;
    edge_key *e = malloc(n * sizeof *e + 1);
    if (!e)
        return 0;
    for (int t = 0; t < mesh->ntris; t++)
        for (int k = 0; k < 3; k++) {
            int a = mesh->tris[t][k], b = mesh->tris[t][(k + 1) % 3];
            edge_key key = {a < b ? a : b, a < b ? b : a, 3 * t + k};
            e[3 * t + k] = key;
        }
    qsort(e, n, sizeof *e, by_edge);
    for (size_t i = 0; i < n; i++)
        across[i] = -1;
    for (size_t i = 0; i < n;) {
        size_t j = i;
        while (j < n && e[j].lo == e[i].lo && e[j].hi == e[i].hi)
            j++;
        if (j - i == 2) {
            across[e[i].slot] = e[i + 1].slot / 3;
            across[e[i + 1].slot] = e[i].slot / 3;
        }
        i = j;
    }
    free(e);
    return 1;
}

static pd_vec3 tri_normal(const pd_mesh *mesh, int t, double *area2)
{
    pd_vec3 a = mesh->verts[mesh->tris[t][0]], b = mesh->verts[mesh->tris[t][1]],
            c = mesh->verts[mesh->tris[t][2]];
    pd_vec3 n = v3_cross(v3_sub(b, a), v3_sub(c, a));
    *area2 = v3_norm(n);
    return v3_unit(n);
}

int viz_scene_build(const pd_mesh *mesh, const viz_frame *f, const viz_view *view,
                    int two_sided, viz_scene *scene)
{
    memset(scene, 0, sizeof *scene);
    size_t nt = (size_t)mesh->ntris;
    scene->faces = malloc(nt * sizeof *scene->faces + 1);
    scene->world = malloc((size_t)mesh->nverts * sizeof *scene->world + 1);
    scene->rank = malloc(nt * sizeof *scene->rank + 1);
    scene->across = malloc(3 * nt * sizeof *scene->across + 1);
    if (!scene->faces || !scene->world || !scene->rank || !scene->across ||
        !link_edges(mesh, scene->across)) {
        viz_scene_free(scene);
        return 0;
    }
    for (int i = 0; i < mesh->nverts; i++)
        scene->world[i] = viz_frame_apply(f, mesh->verts[i]);
    double size = pd_mesh_size(mesh);
    for (int t = 0; t < mesh->ntris; t++) {
        scene->rank[t] = -1;
        double area2;
        pd_vec3 n = viz_frame_rotate(f, tri_normal(mesh, t, &area2));
        if (!(area2 > 2.0 * VIZ_SLIVER_REL * size * size))
            continue;
        double facing = v3_dot(n, view->toward);
        if (!two_sided && facing <= 0.0)
            continue;
        if (facing < 0.0)
            n = v3_neg(n);
        double lit = v3_dot(n, view->light);
        viz_face *face = &scene->faces[scene->nfaces++];
        face->tri = t;
        pd_vec3 c = v3_scale(v3_add(v3_add(scene->world[mesh->tris[t][0]],
                                           scene->world[mesh->tris[t][1]]),
                                    scene->world[mesh->tris[t][2]]), 1.0 / 3.0);
        face->depth = viz_depth(view, c);
        face->shade = VIZ_AMBIENT + (1.0 - VIZ_AMBIENT) * (lit > 0.0 ? lit : 0.0);
    }
    qsort(scene->faces, (size_t)scene->nfaces, sizeof *scene->faces, by_depth);
    for (int i = 0; i < scene->nfaces; i++)
        scene->rank[scene->faces[i].tri] = i;
    return 1;
}

int viz_scene_edge_drawn(const viz_scene *scene, const pd_mesh *mesh, int t, int k)
{
    int m = scene->across[3 * t + k];
    if (m < 0 || scene->rank[m] < 0)
        return 1;
    double a2, b2;
    pd_vec3 na = tri_normal(mesh, t, &a2), nb = tri_normal(mesh, m, &b2);
    if (v3_dot(na, nb) >= cos(VIZ_CREASE_DEG * (M_PI / 180.0)))
        return 0;
    return scene->rank[t] > scene->rank[m];
}
