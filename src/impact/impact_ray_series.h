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

/* The slide onto the diverging ray (impact_rays.h), exact up to the
 * truncation of power series in the angle delta to it. There the slip's
 * direction is attracted (b_1 < 0) while the slip grows (c_0 > 0), so no
 * slide in its basin ends on it: it ends at a normal event, maximum
 * compression or Poisson's end, somewhere along the way. Two series in
 * delta give the way in closed form: H, the regular solution of
 * b H' + c H = 1, so that pz - s H(phi) is constant along a trajectory, and
 * R, with ln s + nu ln|delta| - R(delta) constant (nu = c_0 / |b_1|, the
 * slip's growth against the direction's settling). Then the state at any
 * angle delta_e further along is known, and the event is the root of one
 * equation in ln|delta_e|, found by safeguarded Newton. Built once per
 * collision, like the incoming rays' series. */
/* Terms of the diverging ray's series: 12, as the incoming rays'; 16 and
 * 20 took the same or more instructions on the recorded drops, the build
 * growing as the square (impact_slide.c, OUT_ANGLE). */
enum { PD_RAY_OUT_N = 12 };
typedef struct pd_ray_out {
    int ok;                        /* the ray attracts and the slip grows: the series exist */
    double tx, ty;                 /* the ray's unit direction */
    double nu;                     /* c_0 / |b_1| */
    double h[PD_RAY_OUT_N + 1];    /* H */
    double r[PD_RAY_OUT_N + 1];    /* R (r[0] = 0) */
    double beta[PD_RAY_OUT_N + 1]; /* b / delta, < 0 wherever the series hold */
    double wx, wy;                 /* K_tt^-1 K_tz */
} pd_ray_out;

/* Builds the series of the diverging ray (tx, ty) of K and mu (K as is). */
void pd_ray_out_build(const double K[][3], double mu, double tx, double ty, pd_ray_out *o);

enum { PD_RAY_OUT_COMPRESS, PD_RAY_OUT_PZ };

/* The rest of the slide from the contact velocity u toward the ray of o, up
 * to the event `target`: maximum compression (u_z rises to 0, within
 * ev_tol of it; u.z < 0), or PD_RAY_OUT_PZ, a normal impulse of `goal` more
 * (within ev_tol; goal > 0). Sets the impulse *dp and returns 1; returns 0
 * (and sets nothing) unless u is within max_angle of the ray, delta within
 * half the radius of convergence of every series, u_z rises all along the
 * way (for compression: so the root is the first one), Newton converged,
 * and the truncations' estimated error is at most max_err (units of the
 * impulse). */
int pd_ray_out_tail(const double K[][3], double mu, const pd_ray_out *o, pd_vec3 u, int target,
                    double goal, double ev_tol, double max_angle, double max_err, pd_vec3 *dp);

#endif
