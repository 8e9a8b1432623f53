/* mass.c: volume, centre of mass and inertia tensor of a closed, consistently
 * oriented triangle mesh, per unit density.
 *
 * Exact for the polyhedron: each triangle (a, b, c) spans a signed tetrahedron
 * with a fixed apex r, and the signed tetrahedra of a closed oriented surface
 * add up to the solid (the divergence theorem in discrete form). For a
 * tetrahedron with one corner at the origin and the others at a, b, c,
 * D = a.(b x c) is six times its signed volume and
 *     volume             D / 6
 *     first moment       D / 24 * (a + b + c)
 *     second moment      D / 120 * (a a^T + b b^T + c c^T + s s^T), s = a + b + c
 * the last being the covariance of the canonical tetrahedron, (1/120)(I + 1 1^T),
 * carried to (a, b, c) by the linear map [a b c] of determinant D.
 *
 * The apex r is the centre of the part's bounding box, and every coordinate is
 * taken relative to it before anything is multiplied. With the origin as apex,
 * a 1 m part placed 1e6 m away would sum terms of ~1e12 m^3 to get ~1 m^3 and
 * second moments of ~1e24 to get ~1: every digit lost to cancellation. Relative
 * to r, the terms are of the size of the part and the parallel-axis shift to
 * the centre of mass is by a distance of at most L/2, so nothing cancels.
 *
 * The ten sums (1 volume, 3 first moments, 6 second moments) are accumulated
 * with Neumaier's compensated summation, so their round-off does not grow with
 * the number of triangles (a plain sum of n terms can lose up to n ulps, 1e-11
 * relative for 1e5 triangles; compensated, a few ulps whatever n).
 *
 * Triangles with a repeated vertex index have no area and are skipped, as in
 * pd_mesh_orient. */
#include <math.h>
#include <stddef.h>
#include "posedrop/mass.h"
#include "mesh/mesh_tol.h"
#include "base/fail.h"
#include "mesh/mesh_internal.h"
#include "base/vec3.h"

/* The accumulated quantities, in this order. */
enum { M_VOL, M_X, M_Y, M_Z, M_XX, M_YY, M_ZZ, M_XY, M_YZ, M_ZX, M_COUNT };

/* Neumaier (improved Kahan-Babuska) summation: sum plus a running correction
 * holding the low-order bits each addition dropped. */
typedef struct csum {
    double s, c;
} csum;

static void csum_add(csum *acc, double x)
{
    double t = acc->s + x;
    if (fabs(acc->s) >= fabs(x))
        acc->c += (acc->s - t) + x;
    else
        acc->c += (x - t) + acc->s;
    acc->s = t;
}

static double csum_value(const csum *acc) { return acc->s + acc->c; }

static int tri_degenerate(const int t[3])
{
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

/* Bounding box of the vertices the (non-degenerate) triangles use: its centre
 * is the reference point, its diagonal the part's size. Unused vertices are
 * ignored so that a stray far-away vertex cannot move the reference point off
 * the part. Returns 0 if no triangle has area. */
static int part_box(const pd_mesh *m, pd_vec3 *lo, pd_vec3 *hi)
{
    int any = 0;
    for (int t = 0; t < m->ntris; t++) {
        if (tri_degenerate(m->tris[t]))
            continue;
        for (int k = 0; k < 3; k++) {
            pd_vec3 v = m->verts[m->tris[t][k]];
            if (!any) {
                *lo = *hi = v;
                any = 1;
            }
            *lo = v3_min(*lo, v);
            *hi = v3_max(*hi, v);
        }
    }
    return any;
}

pd_status pd_mass_compute(const pd_mesh *mesh, pd_mass *mass, pd_diag *diag)
{
    if (!mass)
        return pd_fail(diag, PD_ERR_USAGE, "mass: output is NULL");
    pd_status st = pd_mesh_validate(mesh, "mass", diag);
    if (st != PD_OK)
        return st;
    pd_vec3 lo, hi;
    if (!part_box(mesh, &lo, &hi))
        return pd_fail(diag, PD_ERR_COPLANAR, "mass: the mesh has no triangle with area, no volume");
    pd_vec3 r = v3_scale(v3_add(lo, hi), 0.5);
    double size = v3_dist(lo, hi);

    csum acc[M_COUNT] = {{0.0, 0.0}};
    for (int t = 0; t < mesh->ntris; t++) {
        const int *tri = mesh->tris[t];
        if (tri_degenerate(tri))
            continue;
        pd_vec3 a = v3_sub(mesh->verts[tri[0]], r);
        pd_vec3 b = v3_sub(mesh->verts[tri[1]], r);
        pd_vec3 c = v3_sub(mesh->verts[tri[2]], r);
        double d = v3_dot(a, v3_cross(b, c));
        pd_vec3 s = v3_add(v3_add(a, b), c);
        csum_add(&acc[M_VOL], d);
        csum_add(&acc[M_X], d * s.x);
        csum_add(&acc[M_Y], d * s.y);
        csum_add(&acc[M_Z], d * s.z);
        csum_add(&acc[M_XX], d * (a.x * a.x + b.x * b.x + c.x * c.x + s.x * s.x));
        csum_add(&acc[M_YY], d * (a.y * a.y + b.y * b.y + c.y * c.y + s.y * s.y));
        csum_add(&acc[M_ZZ], d * (a.z * a.z + b.z * b.z + c.z * c.z + s.z * s.z));
        csum_add(&acc[M_XY], d * (a.x * a.y + b.x * b.y + c.x * c.y + s.x * s.y));
        csum_add(&acc[M_YZ], d * (a.y * a.z + b.y * b.z + c.y * c.z + s.y * s.z));
        csum_add(&acc[M_ZX], d * (a.z * a.x + b.z * b.x + c.z * c.x + s.z * s.x));
    }
    double sum[M_COUNT];
    for (int i = 0; i < M_COUNT; i++)
        sum[i] = csum_value(&acc[i]);

    double volume = sum[M_VOL] / 6.0;
    double vtol = PD_TOL_VOLUME_REL * size * size * size;
    if (!isfinite(volume) || !isfinite(vtol))
        return pd_fail(diag, PD_ERR_NONFINITE, "mass: volume overflows (part size %g m)", size);
    if (volume <= vtol) {
        if (volume < -vtol)
            return pd_fail(diag, PD_ERR_COPLANAR,
                           "mass: enclosed volume %g m^3 is negative: the faces point inwards "
                           "(orient the mesh first)", volume);
        return pd_fail(diag, PD_ERR_COPLANAR,
                       "mass: enclosed volume %g m^3 is zero within round-off (%g m^3 for a part "
                       "of size %g m): the surface is flat", volume, vtol, size);
    }

    /* Centre of mass relative to r, then second moments about it by the
     * parallel-axis theorem: S_com = S_r - V g g^T, with |g| <= L/2. */
    pd_vec3 g = v3_scale(v3(sum[M_X], sum[M_Y], sum[M_Z]), 1.0 / (24.0 * volume));
    double S[3][3];
    S[0][0] = sum[M_XX] / 120.0 - volume * g.x * g.x;
    S[1][1] = sum[M_YY] / 120.0 - volume * g.y * g.y;
    S[2][2] = sum[M_ZZ] / 120.0 - volume * g.z * g.z;
    S[0][1] = S[1][0] = sum[M_XY] / 120.0 - volume * g.x * g.y;
    S[1][2] = S[2][1] = sum[M_YZ] / 120.0 - volume * g.y * g.z;
    S[2][0] = S[0][2] = sum[M_ZX] / 120.0 - volume * g.z * g.x;

    /* Inertia per unit density: I = trace(S) Id - S (I_xx = integral of
     * y^2 + z^2, I_xy = - integral of x y). */
    pd_mass out;
    out.volume = volume;
    out.com = v3_add(r, g);
    double tr = S[0][0] + S[1][1] + S[2][2];
    int finite = v3_isfinite(out.com);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            out.inertia[i][j] = (i == j ? tr : 0.0) - S[i][j];
            finite = finite && isfinite(out.inertia[i][j]);
        }
    if (!finite)
        return pd_fail(diag, PD_ERR_NONFINITE,
                       "mass: centre of mass or inertia overflows (part size %g m)", size);
    *mass = out;
    return PD_OK;
}
