/* impact_ray_series.h (private): the rest of a slide that ends on an
 * incoming ray (impact_rays.h), exact up to a power series' truncation.
 *
 * In the integrator's parameter tau (dpz/dtau = |u_t| = s) the slip's
 * direction phi and size obey d(phi)/dtau = b(phi), d(ln s)/dtau = c(phi),
 * with b and c trigonometric polynomials of degree 2 fixed by K and mu: the
 * flow is homogeneous of degree 1 in u_t. So the normal impulse left to the
 * origin is s G(phi) with G the solution of b G' + c G = -1 that is regular
 * at the ray phi* (b(phi*) = 0, c(phi*) = its rate < 0), and the tangential
 * impulse follows exactly from u_t = 0 at the end. G's Taylor series in
 * delta = phi - phi* has a recursion of its own (the derivation is at the
 * definition); it converges up to the nearest other root of b, so the tail
 * can take over at any slip and at angles where the third-order expansion
 * it replaced could not. The series depends on K, mu and the ray only:
 * it is built once per collision and ray, and evaluated by Horner. */
#ifndef PD_IMPACT_RAY_SERIES_H
#define PD_IMPACT_RAY_SERIES_H

#include "posedrop/types.h"

/* Terms kept. Building costs ~N^2 multiply-adds, and a term's size falls
 * at least 2x per order within the reach allowed (half the radius of
 * convergence), far more at the angles where tails are taken: measured on
 * the recorded drops and random impacts, 12 terms took as many tails as 24
 * (steps within 0.5%) at a quarter of the build. */
enum { PD_RAY_SERIES_N = 12 };

typedef struct pd_ray_series {
    int ok;                          /* the ray attracts: the series exist */
    double tx, ty;                   /* the ray's unit direction */
    double g[PD_RAY_SERIES_N + 1];   /* G: normal impulse to the origin / s */
    double f[PD_RAY_SERIES_N + 1];   /* F: the part of the normal work / s^2 */
    double wx, wy;                   /* K_tt^-1 K_tz */
} pd_ray_series;

/* Builds the series of the incoming ray (tx, ty) of K and mu (K taken as
 * is), F only with_work. */
void pd_ray_series_build(const double K[][3], double mu, double tx, double ty, int with_work,
                         pd_ray_series *sr);

/* The rest of the slide from the contact velocity u onto the ray of sr:
 * the impulse *dp (contact frame) after which the slip is 0, and,
 * with_work, the normal work *dw. Returns 0 (and sets nothing) unless u is
 * within max_angle of the ray, the normal velocity rises all along the way
 * (so a normal event can only be at its end), delta is within half the
 * radius of convergence, and the truncation's estimated error is at most
 * max_err (units of the impulse; of the work with_work). */
int pd_ray_series_tail(const double K[][3], double mu, const pd_ray_series *sr, pd_vec3 u,
                       double max_angle, double max_err, int with_work, pd_vec3 *dp, double *dw);

#endif
