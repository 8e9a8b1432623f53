/* impact_rays.h (private): the invariant rays of a frictional collision's
 * tangential flow (paper section 5.1, eq. 14 and Figure 7).
 *
 * In the contact frame of impact.h, sliding in the unit direction t changes
 * the tangential velocity at the rate v(t) = a - mu B t per unit normal
 * impulse (a = K_tz, B = K_tt). A ray through the origin along t is invariant
 * when v(t) is parallel to t: v = lambda t. The slip then runs along it at
 * the rate lambda, out of the origin when lambda > 0 (the diverging ray of
 * unstable sticking), into it when lambda < 0 (an incoming ray). Along an
 * invariant ray the impulse direction (-mu t, 1) is constant, so a collision
 * on one is solved in closed form (src/impact/impact_slide.c), and one that ends on
 * an incoming ray as a power series (src/impact/impact_ray_series.c). K is 3 x 3, declared
 * K[][3]: with the sanitizers, GCC's -Wstringop-overflow takes a struct
 * member passed through CONST_M3 for its first row alone. */
#ifndef PD_IMPACT_RAYS_H
#define PD_IMPACT_RAYS_H

#include "posedrop/types.h"

/* The incoming rays of one K and mu: the roots of a trigonometric
 * polynomial of degree 2 (impact_rays.c), so at most PD_RAYS_MAX. */
enum { PD_RAYS_MAX = 4 };

typedef struct pd_rays {
    int n;
    double tx[PD_RAYS_MAX], ty[PD_RAYS_MAX]; /* unit directions */
    double rate[PD_RAYS_MAX];                /* lambda = d|u_t|/dpz along each, < 0 */
} pd_rays;

/* The diverging ray's unit direction (*tx, *ty), or 0 when there is none
 * (sticking is stable, eq. 15, or mu = 0). K is taken as is. */
int pd_ray_diverging(const double K[][3], double mu, double *tx, double *ty);

/* Every incoming ray at which the flow's turning rate changes sign; a ray
 * where it only touches zero (a double root, never met on a real part) is
 * left out. None when the flow turns nowhere (a = 0 and B isotropic: every
 * ray is invariant and the flow needs no snapping). K is taken as is. */
void pd_rays_incoming(const double K[][3], double mu, pd_rays *in);

/* Whether the slip u (tangential part; s = |u_t| > 0) lies in the basin of
 * the diverging ray (rtx, rty) of K and mu: no invariant ray lies between
 * its direction and that ray, so the slip's direction turns onto the ray
 * and meets no other (in the parameter tau of impact_slide.c the
 * direction's flow is autonomous and one-dimensional). 0 where a ray may
 * lie within round-off of that arc, or the direction is opposite the ray.
 * K is taken as is. */
int pd_ray_in_basin(const double K[][3], double mu, double rtx, double rty, pd_vec3 u, double s);

#endif