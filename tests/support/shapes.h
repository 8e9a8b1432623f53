/* shapes.h: test fixtures: a seeded random stream, rigid transforms, and
 * closed meshes of convex solids with known closed-form answers. */
#ifndef PD_TEST_SHAPES_H
#define PD_TEST_SHAPES_H

#include <stdint.h>
#include "posedrop/mesh.h"
#include "posedrop/types.h"

/* splitmix64: tiny, seedable, identical on every platform. */
typedef struct { uint64_t s; } test_rng;
uint64_t rng_next(test_rng *r);
double rng_uniform(test_rng *r);              /* [0, 1) */
double rng_range(test_rng *r, double lo, double hi);
pd_vec3 rng_unit_vector(test_rng *r);        /* uniform on the sphere */

/* C before C23 will not pass a double[3][3] where a const one is expected
 * without a cast: CR(R) is that cast. */
#define CR(m) ((const double(*)[3])(m))

/* A rotation matrix (row-major 3x3), uniform over SO(3). */
void rng_rotation(test_rng *r, double R[3][3]);
pd_vec3 rot_apply(const double R[3][3], pd_vec3 v);

/* x -> scale * R x + t on every vertex of a mesh, or of a point array. */
void mesh_transform(pd_mesh *m, const double R[3][3], double scale, pd_vec3 t);
void points_transform(pd_vec3 *p, int n, const double R[3][3], double scale, pd_vec3 t);

/* A closed, outward-oriented triangle mesh of the convex hull of a small point
 * set (n <= ~200), found by brute force over all triples: an oracle that shares
 * no code with the library's hull. Every point on the hull's boundary becomes a
 * mesh vertex; each planar face is fanned around its centroid-sorted loop.
 * Returns NULL for degenerate input. Free with pd_mesh_free. */
pd_mesh *convex_mesh(const pd_vec3 *pts, int n);

/* Number of distinct facet planes found by the same brute force. */
int convex_facet_count(const pd_vec3 *pts, int n);

/* Point sets of standard solids, centred at the origin. Each returns the count
 * and writes into out (room for at least 64 points). */
int pts_box(double ax, double ay, double az, pd_vec3 *out);   /* edge lengths */
/* 2 nsides points: n <= 32 in the 64 points above, more given room. */
int pts_prism(int nsides, double radius, double height, pd_vec3 *out);
int pts_tetrahedron(pd_vec3 *out);
/* A prism over the parallelogram (0,0) (1,0) (2,1) (1,1) in the x-z plane,
 * depth 1 in y (8 points): its centroid (1, 0.5, 0.5) projects exactly onto
 * the edge x = 1 of its bottom and of its top, two knife edges. */
int pts_parallelogram_prism(pd_vec3 *out);
/* A regular pyramid, flat when height << 1: nsides (<= 64) corners of
 * circumradius 1 on z = 0 (the first on +x) and the apex at (0, 0, height). */
int pts_flat_pyramid(int nsides, double height, pd_vec3 *out);
int pts_cube(pd_vec3 *out);
int pts_octahedron(pd_vec3 *out);
int pts_dodecahedron(pd_vec3 *out);
int pts_icosahedron(pd_vec3 *out);

/* A closed mesh of a hull's facets (each fanned from its first corner), so a
 * point cloud can go through pd_part_build like a file would. */
struct pd_hull;
pd_mesh *mesh_of_hull(const struct pd_hull *h);

/* A part built from mesh m (consumed; NULL gives NULL), with its centre of
 * mass given if com is not NULL; NULL on failure, which is printed with the
 * library's message. */
struct pd_part;
struct pd_diag;
struct pd_part *part_of(pd_mesh *m, const pd_vec3 *com, struct pd_diag *diag);

/* The part of the hull of n (<= 64) random points on the ellipsoid of
 * half-axes 1, ay, az, its centre of mass drawn from [-cx, cx] x [-cy, cy] x
 * {0} (points first, then the centre, from rng). */
struct pd_part *part_random_ellipsoid(test_rng *rng, int n, double ay, double az, double cx,
                                      double cy);

/* Points of a regular n-gon prism (radius 1, height 1) or pyramid (apex at
 * z = 1 over the base ring at z = -0.5), for n beyond the fixtures' 32, and
 * their distortions. */
typedef struct {
    int nsides;
    int pyramid;
    double twist;   /* top ring turned by this (rad) */
    double pair;    /* each corner doubled this far round its ring (rad), or 0 */
    double noise;   /* each point moved at random by up to this x PD_TOL_SYMMETRY_REL x size */
    int digits;     /* coordinates printed to this many significant digits, as
                       an exporter would, in millimetres of a 12 mm part placed
                       off the origin; 0: not */
    int float32;    /* coordinates rounded to float, as binary STL, in that frame */
} ring_spec;

/* The points of r (malloc'd, *n of them); noise drawn from rng. */
pd_vec3 *ring_points(const ring_spec *r, test_rng *rng, int *n);

/* A part of r's points through the library's hull (convex_mesh takes at
 * most ~200 points), moved by x -> scale R x + t first if R is not NULL;
 * noise from a fixed seed. NULL on failure. */
struct pd_part *ring_part(const ring_spec *r, const double R[3][3], double scale, pd_vec3 t);

/* Chi-square test that a Monte Carlo result is uniform over its poses:
 * P(X > statistic) with nposes - 1 degrees of freedom. */
struct pd_sim_result;
double uniform_p_value(const struct pd_sim_result *r);

/* The part of the hull of n points (pd_hull_build, then pd_part_build on
 * its facets): PD_OK and *part, or the first refusal, its message in diag
 * (may be NULL); nothing printed. */
struct pd_part;
pd_status part_of_points(const pd_vec3 *pts, int n, struct pd_part **part, struct pd_diag *diag);

/* Convenience: convex_mesh of the points above. */
pd_mesh *mesh_box(double ax, double ay, double az);

/* The part of mesh m (consumed) and its static estimate; 0, both NULL, on
 * failure. */
struct pd_static_result;
int mesh_part(pd_mesh *m, struct pd_part **part, struct pd_static_result **poses);
pd_mesh *mesh_prism(int nsides, double radius, double height);

/* A w x d x h box (x, y, z) whose bottom is a shallow roof: two facets
 * meeting along the y axis at z = 0, each tilted ridge / 2 (rad) up toward
 * x = +-w/2. With the centre of mass above the ridge, both roof facets are
 * stable, and the energy barrier between them is the rise of the centre of
 * mass from lying on one to balancing on the ridge, about c (1 - cos(ridge/2))
 * for c its height: tiny for a ridge of a degree. */
pd_mesh *mesh_roof_box(double w, double d, double h, double ridge);

#endif
