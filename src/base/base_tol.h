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

/* The radius of a part's corners, times its size L, behind the contact
 * patch of drilling friction: the impulse engine's (src/sim/sim_model.c)
 * and ODE's (src/engines/engine_ode.c); docs/contact.md. Why 0.0289: it is
 * the corner the default contact time rests on (about 0.5 mm on a 1 cm
 * cube, diagonal 1.73 cm: Hertz's estimate of 5e-4 s), kept in proportion
 * to the size as that estimate keeps it. The patch radius goes as its
 * square root: a part with sharper corners spins longer. */
#define PD_CORNER_RADIUS_REL (0.5e-3 / (0.01 * 1.7320508075688772935))

#endif
