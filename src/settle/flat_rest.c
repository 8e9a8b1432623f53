/* flat_rest.c: a part lying flat on a stable facet stays there (see
 * flat_rest.h).
 *
 * While the part lies flat, sliding and spinning about the vertical, the
 * floor must supply, about the centre of mass, a horizontal torque of at most
 *   mu m g h                         friction (at most mu m g, h below),
 * + tilt (wn^2 + |dwn/dt|)           the gyroscopic and the spin's own
 *                                    torque when the normal n is not a
 *                                    principal axis,
 * with wn^2 <= 2 KE / inn (the kinetic energy only falls while flat: the
 * normal forces do no work, friction only takes) and |dwn/dt| <= mu m g
 * reach / inn (friction's torque about the vertical). The normal pressure
 * gives that torque by moving its centre a distance d = torque / (m g) from
 * the centre of mass's foot, which stays a non-negative pressure while d is
 * less than the foot's distance to the facet's boundary. Then a motion that
 * stays flat exists for good; the rigid model is taken to follow it.
 *
 * A part in a drop is never exactly flat: microcollisions leave it rocking
 * and tilted (drop.c). Its rocking energy (the kinetic energy beyond the
 * flat motion's, plus its height above lying flat on the facet's lowest
 * corner) is bounded against the edge the tilted pressure leaves: with the
 * centre of pressure at d, the nearest edge holds the part like an edge at
 * inside - d, whose barrier is sqrt((inside - d)^2 + h^2) - h. The rocking
 * energy plus the rest fall (the depth a contact may have sunk) must stay
 * below that barrier by the factor PD_FLAT_SAFETY. This is the energy test
 * of basin.c for the rocking alone, with the sliding energy set apart by
 * the bound above; it is an argument, not a proof (friction's direction
 * turns as the part slides), and test_drop checks it against drops run to
 * the end without it. */
#include <math.h>
#include "settle/flat_rest.h"
#include "settle/settle_tol.h"
#include "base/vec3.h"

void pd_flat_build(const pd_body *b, const pd_hull *hull, const pd_static_result *descent,
                   pd_flat_facet *out)
{
    for (int f = 0; f < hull->nfacets; f++) {
        pd_flat_facet *F = &out[f];
        pd_vec3 n = quat_rotate_inv(b->frame, hull->normal[f]);
        F->n = n;
        F->h = hull->offset[f] - v3_dot(hull->normal[f], b->com);
        pd_vec3 In = v3(b->moment[0] * n.x, b->moment[1] * n.y, b->moment[2] * n.z);
        F->inn = v3_dot(n, In);
        F->tilt = v3_norm(v3_sub(In, v3_scale(n, F->inn)));
        F->inside = 0.0;
        F->reach = 0.0;
        if (descent->facets[f].rest != f)
            continue;
        int base = hull->facet_start[f], k = hull->facet_start[f + 1] - base;
        pd_vec3 foot = v3_scale(n, F->h);
        double inside = INFINITY;
        for (int i = 0; i < k; i++) {
            pd_vec3 a = b->verts[hull->facet_vert[base + i]];
            pd_vec3 c = b->verts[hull->facet_vert[base + (i + 1) % k]];
            pd_vec3 e = v3_sub(c, a);
            /* Corners run counter-clockwise seen from outside: the inside is
             * to the left of each edge. */
            inside = fmin(inside, v3_dot(n, v3_cross(e, v3_sub(foot, a))) / v3_norm(e));
            F->reach = fmax(F->reach, v3_norm(v3_sub(a, v3_scale(n, v3_dot(a, n)))));
        }
        F->inside = inside > 0.0 ? inside : 0.0;
    }
}

/* The factor at which pd_flat_settled refuses before its pass over the
 * corners (below), shared by pd_flat_height_max (tolerances.h). */
#define EARLY_SAFETY (PD_FLAT_EARLY_SHARE * PD_FLAT_SAFETY)

double pd_flat_height_max(const pd_flat_facet *ff, int nfacets)
{
    /* pd_flat_settled's early refusal holds once EARLY_SAFETY (z - h) reaches
     * the largest barrier the facet can give, sqrt(inside^2 + h^2) - h (no
     * tilting torque), its rocking energy being at least z - h. */
    double zmax = -INFINITY;
    for (int f = 0; f < nfacets; f++) {
        const pd_flat_facet *F = &ff[f];
        if (F->inside > 0.0)
            zmax = fmax(zmax, F->h + (sqrt(F->inside * F->inside + F->h * F->h) - F->h) /
                                         EARLY_SAFETY);
    }
    return zmax;
}

int pd_flat_settled(const pd_flat_facet *ff, const pd_body *b, const pd_state *s, int f, double g,
                    double mu, double rest_fall)
{
    const pd_flat_facet *F = &ff[f];
    if (!(F->inside > 0.0))
        return 0;
    /* The flat motion's kinetic energy: the horizontal velocity, and the
     * spin about n in the inertia metric (the largest share of the spin
     * that keeps the facet in its plane). */
    const pd_vec3 w = s->w;
    pd_vec3 In = v3(b->moment[0] * F->n.x, b->moment[1] * F->n.y, b->moment[2] * F->n.z);
    double wn = v3_dot(w, In) / F->inn;
    double ke = pd_body_kinetic(b, s);
    double ke_flat = 0.5 * b->mass * (s->v.x * s->v.x + s->v.y * s->v.y) + 0.5 * F->inn * wn * wn;
    double mg = b->mass * g;
    double d = mu * F->h + F->tilt * (2.0 * ke_flat / F->inn + mu * mg * F->reach / F->inn) / mg;
    double hold = F->inside - d;
    if (!(hold > 0.0))
        return 0;
    double barrier = sqrt(hold * hold + F->h * F->h) - F->h;
    /* Rocking energy per unit weight: height above lying flat on the lowest
     * corner, any height of that corner above the floor, and the kinetic
     * energy beyond the flat motion's. The first two sum to at least
     * s->x.z - h whatever the lowest corner's height, so most refusals need
     * no pass over the corners (a coin's cap has 32). Refused here only
     * beyond the bound by PD_FLAT_EARLY_SHARE, so that the round-off of the
     * two sums never refuses what the exact test below would take. */
    double rock_least = (s->x.z - F->h) + (ke - ke_flat) / mg;
    if (!(barrier > EARLY_SAFETY * (fmax(rock_least, 0.0) + rest_fall)))
        return 0;
    int base = b->facet_start[f], k = b->facet_start[f + 1] - base;
    double zmin = INFINITY;
    for (int i = 0; i < k; i++)
        zmin = fmin(zmin, s->x.z + quat_rotate(s->q, b->verts[b->facet_vert[base + i]]).z);
    double rock = (s->x.z - zmin - F->h) + fmax(zmin, 0.0) + (ke - ke_flat) / mg;
    return barrier > PD_FLAT_SAFETY * (fmax(rock, 0.0) + rest_fall);
}
