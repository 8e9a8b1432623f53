/* impact_collision.h (private to the impact layer): the state of one
 * collision while it is solved, in the units of impact.c (|u0| = 1, K's
 * mean diagonal 1), and the steps every phase takes on it. The sliding
 * phase (impact_slide.h) builds on it; the solver (impact.c) on both. */
#ifndef PD_IMPACT_COLLISION_H
#define PD_IMPACT_COLLISION_H

#include <math.h>
#include "base/gsl_adapter.h"
#include "impact/impact.h"
#include "impact/impact_ray_series.h"
#include "impact/impact_rays.h"
#include "base/mat3.h"
#include "base/vec3.h"

/* State of the sliding ODE: the impulse so far, and the normal work W, last:
 * Poisson's law never reads W, so it integrates only the first NSTATE_P
 * (an rk8pd step's cost grows with the dimension, 4/3 of it with W). */
enum { PX, PY, PZ, PW, NSTATE };
enum { NSTATE_P = PW };

/* The normalised problem and the running state of one collision. */
typedef struct {
    double K[3][3];
    pd_vec3 u0;
    double mu, e;
    pd_impact_law law;
    double tol;       /* the integrator's local error per step (absolute and relative) */
    double y[NSTATE]; /* p = (px, py, pz) and W so far */
    int ray_known;    /* have_ray and (rtx, rty) are set (coll_have_ray) */
    int have_ray;     /* sticking is unstable: the diverging ray (rtx, rty) exists */
    double rtx, rty;
    int on_ray;       /* sliding stopped on that ray */
    pd_rays in;       /* the incoming rays */
    unsigned built;   /* bit k: ser[k] is built (once the slip comes near ray k) */
    pd_ray_series *ser; /* [PD_RAYS_MAX], the slide's: left out of the collision's zeroing */
    pd_ray_out *out;    /* the diverging ray's series, the slide's likewise */
    int out_built;      /* out is built (once the slip's direction comes near the ray) */
    double out_refused; /* the angle at which out's tail was last refused (0: never) */
    int compressed;
    double pz_c, W_c, pz_end, W_end;
    int done;
} collision;

/* The velocity is always u0 + K p, never integrated, so u1 = u0 + K p holds
 * exactly and the energy bookkeeping p.(u0 + u1)/2 matches the work. */
static inline pd_vec3 coll_u(const collision *c, const double y[])
{
    return v3_add(c->u0, m3_vec(c->K, v3(y[PX], y[PY], y[PZ])));
}

/* Whether the diverging ray exists, found the first time it is asked: a
 * collision whose slip never comes near an invariant ray and never sticks
 * (most microcollisions of a sliding part: one step onto maximum
 * compression) never needs it. */
static inline int coll_have_ray(collision *c)
{
    if (!c->ray_known) {
        c->have_ray = pd_ray_diverging(CONST_M3(c->K), c->mu, &c->rtx, &c->rty);
        c->ray_known = 1;
    }
    return c->have_ray;
}

/* Marks maximum compression at the current state and sets the end target. */
static inline void coll_compress(collision *c)
{
    c->compressed = 1;
    c->pz_c = c->y[PZ];
    c->W_c = c->y[PW];
    c->pz_end = (1.0 + c->e) * c->pz_c;
    /* Stronge: restitution work -e^2 W_c, so the total normal work ends at
     * (1 - e^2) W_c (W_c <= 0). */
    c->W_end = (1.0 - c->e * c->e) * c->W_c;
    if (c->e == 0.0)
        c->done = 1;
}

/* Advances by h along a constant impulse direction d = p', with
 * q = (K d)_z and uz the normal velocity at the start. */
static inline void linear_advance(collision *c, pd_vec3 d, double q, double uz, double h)
{
    c->y[PX] += h * d.x;
    c->y[PY] += h * d.y;
    c->y[PW] += h * uz + 0.5 * q * h * h;
    c->y[PZ] += h;
}

/* The step h with A h + B h^2 / 2 = dw (the normal work along a step whose
 * normal velocity starts at A and grows at B), as 2 dw / (A + sqrt(A^2 +
 * 2 B dw)), the form that does not cancel for A >= 0; NaN if there is none. */
static inline double work_step(double A, double B, double dw)
{
    double disc = A * A + 2.0 * B * dw;
    double den = disc >= 0.0 ? A + sqrt(disc) : 0.0;
    return den > 0.0 ? 2.0 * dw / den : (double)NAN;
}

#endif
