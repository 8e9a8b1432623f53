/* viz_const.h: the fixed choices of the pictures, each with why. */
#ifndef PD_VIZ_CONST_H
#define PD_VIZ_CONST_H

/* The eye: azimuth -60 deg, elevation 25 deg. Low enough that the part
 * stands on its floor rather than being seen from above, high enough that a
 * flat part's top shows; off the axes so that no face of a box is seen
 * edge-on. */
#define VIZ_VIEW_AZ_DEG (-60.0)
#define VIZ_VIEW_EL_DEG 25.0

/* Flat shading: brightness = ambient + (1 - ambient) * max(0, n . light).
 * 0.35 keeps faces turned from the light readable against white paper. */
#define VIZ_AMBIENT 0.35

/* Mesh edges drawn as lines: outlines, and creases whose faces' normals
 * differ by more than this. 30 deg keeps the facets of a 32-sided
 * revolution (11.25 deg apart) smooth while a box's edges (90 deg) and a
 * chamfer's (45 deg) show. */
#define VIZ_CREASE_DEG 30.0

/* Triangles whose area is below this fraction of size^2 have no reliable
 * normal (a sliver left by welding) and are skipped: at 1e-12 they are far
 * below a hundredth of a pixel at any panel size. */
#define VIZ_SLIVER_REL 1e-12

/* Great-circle arcs of the gauss-sphere map are drawn as polylines with at
 * most this angle (deg) between points: the largest gap from the true arc
 * is r (1 - cos(a/2)) = 4e-5 r, under 0.01 px on a 150 px disc. */
#define VIZ_ARC_STEP_DEG 1.0

/* A measured distribution given as p must sum to 1 within this: published
 * percentages rounded to 0.1 % over ten poses are off by at most 0.5 %,
 * while a table in percent (summing to 100) or with a missing row is far
 * outside. */
#define VIZ_MEASURED_SUM_TOL 0.01

/* The sensitivity's words call a parameter one that moves a pose when its
 * lower and upper thirds' intervals are apart, or when the lower end of its
 * index's 95% interval is above this: a share of the pose's variance clear
 * of noise. Small, because a pose indicator's variance p (1 - p) is mostly
 * the drop's own randomness: p going from 0.2 to 0.7 across a range is an
 * index of 0.08. */
#define VIZ_SENS_DETECT 0.01

#endif
