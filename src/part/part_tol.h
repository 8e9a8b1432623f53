/* part_tol.h (private): the part model's acceptance test. Conventions as in
 * posedrop/tolerances.h. */
#ifndef PD_PART_TOL_H
#define PD_PART_TOL_H

#include "posedrop/tolerances.h"

/* The centre of mass must lie at least this far inside every hull facet
 * plane; closer is "on the hull" and the part is refused (it would balance on
 * a facet it touches with its own centre). Same bound as the plane tolerance:
 * the hull itself is only known to that accuracy. */
#define PD_TOL_COM_INSIDE_REL PD_TOL_PLANE_REL

/* A solid's second moments along every direction are positive, and so are
 * its principal moments of inertia (each the sum of two second moments).
 * A computed second moment below minus this fraction of the largest is
 * negative beyond round-off: the mesh is not the surface of a solid (it
 * passes through itself, or part of it is inside out, so that some of its
 * volume counts negatively), and the part is refused. A smallest principal
 * moment below this fraction of the largest is not resolved by the
 * arithmetic: the part is refused as too thin, a rod of radius below
 * sqrt(this / 6) = 1.3e-5 of its length (the drops would divide by round-off).
 * Why 1e-9: the tetrahedra of a part of thickness t have volumes relative
 * error ~1e-16 L / t, so the moments of a part as flat as the hull accepts
 * (t = PD_TOL_PLANE_REL L) carry ~1e-10 of the largest (measured: flat
 * pyramids of t = 3e-7 L, turned and moved off the origin, reach -3e-11);
 * 1e-9 leaves a margin of 10. A fold through the part gives moments of
 * order the largest (-65 times it for a button of the paper's). Smaller: flat
 * parts would be refused for their round-off; larger: rods of radius
 * 1e-4 L (a 10 cm pin of 10 um) would be. */
#define PD_TOL_INERTIA_REL 1e-9

/* The solid lies within its convex hull, so its volume is at most the
 * hull's and its second moment about any point, along any direction, at
 * most the hull's. The hull is exact only up to PD_TOL_PLANE_REL: a mesh
 * vertex within that distance of a hull facet is not a hull corner, and a
 * merged facet's corners lie that far off one plane. So the solid may reach
 * outside the hull as fanned from its corners by a shell this thick (times
 * L): twice the plane tolerance, for a point on one side and a corner on the
 * other, and twice that again for margin. A mesh whose volume or moments
 * exceed the hull's by more than that shell can hold counts some volume
 * twice (shells that overlap, a surface folded through itself). */
#define PD_TOL_SOLID_SHELL_REL (4.0 * PD_TOL_PLANE_REL)

#endif
