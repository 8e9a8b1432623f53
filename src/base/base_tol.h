/* base_tol.h (private): tolerances shared by several layers above base. The
 * public ones, which users reason about, are in posedrop/tolerances.h; this
 * file follows its conventions (lengths relative to the part's size L,
 * angles in radians, each value with why and what breaks either way). */
#ifndef PD_BASE_TOL_H
#define PD_BASE_TOL_H

/* Angles between unit vectors below this, and unit vectors' length errors
 * below it, are round-off. Quasi-static descent works on the unit sphere of
 * gravity directions: an exit point of a vertex region closer than this angle
 * to a facet normal is snapped to it, and a descent step shorter than this is
 * a knife edge. pd_hull_check refuses a facet normal whose length is off 1 by
 * more; two directions closer than this are parallel.
 * Why 1e-12 rad (6e-11 deg): unit vectors carry round-off ~1e-16; facet normals
 * that must stay distinct differ by 1e-7 rad or more (see PD_TOL_PLANE_REL). */
#define PD_TOL_ANGLE 1e-12

#endif
