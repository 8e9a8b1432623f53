/* project.h: the picture of a part resting in one pose: its frame on the
 * floor, a fixed oblique orthographic view, back-face culling, flat shading
 * and the painter's order over the input mesh's triangles.
 *
 * The painter's order (far to near by the depth of each triangle's centroid,
 * after the triangles facing away are dropped) is exact for a convex part:
 * its front faces never overlap. On a non-convex part two front faces can
 * overlap, and the order is wrong when a large face's centroid lies nearer
 * than a smaller face it actually hides behind (long faces beside short
 * ones, faces seen through an opening such as the bore of a cup); cyclic
 * overlaps have no right order at all. The test suite measures how often
 * that happens against a depth buffer (tests/unit/test_viz.c). */
#ifndef PD_VIZ_PROJECT_H
#define PD_VIZ_PROJECT_H

#include "posedrop/part.h"
#include "posedrop/types.h"

/* An orthographic view: screen axes right and up, and toward, the unit
 * vector from the scene to the eye (larger dot(p, toward) is nearer). */
typedef struct viz_view {
    pd_vec3 right, up, toward;
    pd_vec3 light;   /* unit vector toward the light, world frame */
} viz_view;

/* The view every panel uses: the eye at azimuth az and elevation el
 * (radians) about the world's vertical z, the light above the eye's left
 * shoulder so that the three faces of a box seen from it shade apart. */
void viz_view_oblique(double az, double el, viz_view *view);
void viz_view_default(viz_view *view);

/* A part resting on a facet: world = R (x - foot), with world z up (the
 * facet's outward normal n maps to -z), the floor at z = 0 and the centre of
 * mass straight above the origin. R's rows are the world axes in the part's
 * frame; x_w is the part's frame axis least aligned with n, made horizontal,
 * so that one part looks the same way in every pose where it can. */
typedef struct viz_frame {
    pd_vec3 row[3];
    pd_vec3 foot;    /* the centre of mass projected onto the facet's plane */
} viz_frame;

void viz_frame_of(pd_vec3 com, pd_vec3 normal, double offset, viz_frame *f);
pd_vec3 viz_frame_apply(const viz_frame *f, pd_vec3 x);
pd_vec3 viz_frame_rotate(const viz_frame *f, pd_vec3 v);

/* A point of the screen (user units before the panel's scale; y up). */
typedef struct viz_pt {
    double x, y;
} viz_pt;

viz_pt viz_project(const viz_view *view, pd_vec3 world);
double viz_depth(const viz_view *view, pd_vec3 world);

/* The triangles to draw, far to near. */
typedef struct viz_face {
    int tri;         /* triangle index in the mesh */
    double depth;    /* of its centroid: the painter's key */
    double shade;    /* brightness in [VIZ_AMBIENT, 1] */
} viz_face;

typedef struct viz_scene {
    int nfaces;
    viz_face *faces;   /* drawing order */
    pd_vec3 *world;    /* every mesh vertex in the world frame */
    int *rank;         /* per triangle: its place in faces, -1 if not drawn */
    int *across;       /* per triangle edge (3 t + k, edge from corner k to
                          k + 1): the triangle across it, -1 on a boundary */
} viz_scene;

/* Lays out the mesh in frame f for view. two_sided: the mesh is not closed,
 * so no face may be culled (its inside shows through the opening) and a
 * face is lit on the side that faces the eye. Returns 0 when out of memory
 * (scene then empty). */
int viz_scene_build(const pd_mesh *mesh, const viz_frame *f, const viz_view *view,
                    int two_sided, viz_scene *scene);
void viz_scene_free(viz_scene *scene);

/* Whether the edge k of triangle t is drawn as a line: an outline (the face
 * across is not drawn or there is none) or a crease (normals more than
 * VIZ_CREASE_DEG apart), drawn with the nearer of its two faces so that the
 * later fill does not cover half of it. */
int viz_scene_edge_drawn(const viz_scene *scene, const pd_mesh *mesh, int t, int k);

#endif
