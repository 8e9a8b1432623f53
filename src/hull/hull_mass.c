/* hull_mass.c: the solid convex hull's volume and second moments (see
 * hull_mass.h), for parts whose own mass properties are unknown and for
 * checking those that are known against the hull that contains them. */
#include "hull/hull_mass.h"
#include "base/vec3.h"

/* Each facet is fanned from its first corner into tetrahedra with apex c.
 * For the tetrahedron (0, a, b, d) of volume v the second moment is
 * v/20 (a a^T + b b^T + d d^T + s s^T) with s = a + b + d (the standard
 * closed form, e.g. Tonon, J. Math. Stat. 1 (2004) 8). */
void pd_hull_moments(const pd_hull *h, pd_vec3 c, double *volume, double S[3][3])
{
    double vol = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            S[i][j] = 0.0;
    for (int f = 0; f < h->nfacets; f++) {
        int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
        pd_vec3 a = v3_sub(h->verts[h->facet_vert[k0]], c);
        for (int k = k0 + 1; k + 1 < k1; k++) {
            pd_vec3 b = v3_sub(h->verts[h->facet_vert[k]], c);
            pd_vec3 d = v3_sub(h->verts[h->facet_vert[k + 1]], c);
            double v = v3_dot(a, v3_cross(b, d)) / 6.0;
            vol += v;
            pd_vec3 s = v3_add(v3_add(a, b), d);
            const pd_vec3 *p[4] = {&a, &b, &d, &s};
            for (int m = 0; m < 4; m++) {
                double x[3] = {p[m]->x, p[m]->y, p[m]->z};
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++)
                        S[i][j] += v / 20.0 * x[i] * x[j];
            }
        }
    }
    *volume = vol;
}
