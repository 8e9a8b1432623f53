/* mesh_tol.h (private): tolerances of mass properties and shell orientation.
 * Conventions as in posedrop/tolerances.h. */
#ifndef PD_MESH_TOL_H
#define PD_MESH_TOL_H

/* A closed mesh whose enclosed volume is at most this times L^3 has no volume
 * (a flat or doubled surface, or one whose faces point inwards) and is refused
 * by pd_mass_compute. Why 1e-12: the volume is a sum of signed tetrahedra taken
 * from a point of the part, each with round-off of a few 1e-16 of its own
 * size, so a flat surface of area A comes out at ~1e-16 A L; even a finely
 * folded surface of a thousand L^2 stays below 1e-13 L^3. A genuine part of
 * size L has at least one extent much larger than 1e-12 L (a sheet 1 um thick
 * over a 1 m outline is 1e-6 L^3). Larger: thin but real plates and shims
 * would be refused. Smaller: round-off of a flat surface could pass as a
 * volume and give a centre of mass and inertia that are pure noise. */
#define PD_TOL_VOLUME_REL 1e-12

/* pd_mesh_orient decides whether one connected shell lies inside another by
 * the winding number of the other shell at a point of the first: 1 inside, 0
 * outside, exact integers up to round-off of a few 1e-16 per triangle. A point
 * that lies on the other shell (shells touching along a face) sees 1/2. A
 * winding number farther than this from every integer is such a touching
 * point, and another point of the shell is tried. Why 0.25: halfway between
 * the integer a clean point gives and the 1/2 a touching point gives, so
 * neither round-off (tiny) nor a touch (exactly 1/2) is mistaken for the
 * other. */
#define PD_TOL_WINDING 0.25

/* The self-crossing search (mesh_selfx.c) passes a pair of triangles to its
 * exact test unless a projection of bounding boxes sets them apart. Each
 * projection is a few dot products of coordinates of magnitude R (the largest
 * of the welded mesh) with unit vectors orthonormal to round-off, off by a
 * few 1e-16 R; it is widened by this times R, a thousandfold margin, so that
 * rounding never drops a pair that crosses. Larger: pairs apart by less are
 * tested exactly (slower, never wrong). Smaller than the round-off: a
 * crossing pair could be missed. */
#define PD_SELFX_PAD_REL 1e-12

/* The same for the boxes of directions from a shared vertex (unit vectors,
 * and the meeting point of two tangents of at most 1/(1 - cos 120 deg) = 2
 * away: round-off of a few 1e-16): an absolute widening with the same
 * margin. */
#define PD_SELFX_ARC_PAD 1e-12

/* The caps of directions of the narrowed search (mesh_selfx.c, shadow_subset):
 * each triangle's directions from o lie in a cap about the mean of its
 * corners' unit directions, of chord radius r computed from unit vectors
 * (round-off a few 1e-16). r is scaled by 1 + PD_SELFX_CAP_ROUND_REL and
 * widened by PD_SELFX_CAP_PAD, and two caps meet within another
 * PD_SELFX_CAP_PAD: far above that round-off, and above the rounding of the
 * cells the caps are hashed into, so that no pair of triangles that cross is
 * left out of the search. Larger: more triangles searched (slower, never
 * wrong); below the round-off, a crossing could be missed. */
#define PD_SELFX_CAP_ROUND_REL 1e-12
#define PD_SELFX_CAP_PAD 1e-9

/* The kernel point o of the star-shaped test and of the narrowing is only
 * proposed in floating point (exact signs then decide), so these set its
 * cost, never an answer: the linear program's feasibility tolerance, 1e-15
 * of the bounding diagonal (round-off of the planes' offsets); the least
 * inscribed radius, 1e-12 of it, below which the kernel counts as empty; and
 * the share of that radius, 1 - 1e-9, by which a plane must hold the centre
 * not to be added to the next round. */
#define PD_SELFX_KERNEL_LP_TOL_REL 1e-15
#define PD_SELFX_KERNEL_RADIUS_REL 1e-12
#define PD_SELFX_KERNEL_INSIDE_SHARE (1.0 - 1e-9)

#endif
