/* body.c: the rigid-body model of a part for dynamics (see body.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "dynamics/body.h"
#include "base/fail.h"
#include "dynamics/dynamics_tol.h"
#include "hull/hull_mass.h"
#include "base/vec3.h"

static int cmp_int(const void *a, const void *b)
{
    int x = *(const int *)a, y = *(const int *)b;
    return (x > y) - (x < y);
}

/* Vertex -> edge neighbours and vertex -> facets, from the facet loops. Each
 * undirected edge appears once in each of its two facets, so the neighbour
 * lists are sorted and deduplicated. */
static pd_status build_adjacency(pd_body *b, const pd_hull *h)
{
    int n = h->nverts, nk = h->facet_start[h->nfacets];
    b->adj_start = calloc((size_t)n + 1, sizeof *b->adj_start);
    b->vf_start = calloc((size_t)n + 1, sizeof *b->vf_start);
    b->adj = malloc(sizeof *b->adj * (size_t)(2 * nk));
    b->vf = malloc(sizeof *b->vf * (size_t)nk);
    int *fill = calloc((size_t)n, sizeof *fill);
    if (!b->adj_start || !b->vf_start || !b->adj || !b->vf || !fill) {
        free(fill);
        return PD_ERR_NOMEM;
    }
    for (int k = 0; k < nk; k++) {
        b->adj_start[h->facet_vert[k] + 1] += 2;
        b->vf_start[h->facet_vert[k] + 1] += 1;
    }
    for (int i = 0; i < n; i++) {
        b->adj_start[i + 1] += b->adj_start[i];
        b->vf_start[i + 1] += b->vf_start[i];
    }
    for (int f = 0; f < h->nfacets; f++) {
        int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
        for (int k = k0; k < k1; k++) {
            int v = h->facet_vert[k];
            int next = h->facet_vert[k + 1 < k1 ? k + 1 : k0];
            int prev = h->facet_vert[k > k0 ? k - 1 : k1 - 1];
            b->adj[b->adj_start[v] + fill[v]++] = next;
            b->adj[b->adj_start[v] + fill[v]++] = prev;
            b->vf[b->vf_start[v] + (fill[v] / 2 - 1)] = f;
        }
    }
    /* Compact the doubled neighbour lists in place. */
    int out = 0;
    for (int i = 0; i < n; i++) {
        int s0 = b->adj_start[i], s1 = b->adj_start[i + 1];
        qsort(b->adj + s0, (size_t)(s1 - s0), sizeof *b->adj, cmp_int);
        b->adj_start[i] = out;
        for (int k = s0; k < s1; k++)
            if (k == s0 || b->adj[k] != b->adj[k - 1])
                b->adj[out++] = b->adj[k];
    }
    b->adj_start[n] = out;
    free(fill);
    return PD_OK;
}

/* Marks the vertices where pd_body_support must polish. Hill-climbing stops
 * at a vertex v lower than its edge neighbours prev and next on a facet F;
 * another corner u of F is u - v = a (prev - v) + b (next - v) + c n, n the
 * unit normal of the plane through prev, v and next, so for a unit direction
 * d it lies lower than v by at most |c| when a, b >= 0 (d . (prev - v) and
 * d . (next - v) are >= 0). A planar convex facet has c = 0 and a, b >= 0 for
 * every corner; polishing v is needed only where some facet around it has a
 * corner with |c| above PD_TOL_SUPPORT_FLAT_REL or outside the angle at v. */
static void mark_polish(pd_body *b, const pd_hull *h)
{
    double tau = PD_TOL_SUPPORT_FLAT_REL * b->size;
    for (int f = 0; f < h->nfacets; f++) {
        int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
        for (int k = k0; k < k1 && k1 - k0 > 3; k++) {
            int v = h->facet_vert[k];
            pd_vec3 p = b->verts[v];
            pd_vec3 e1 = v3_sub(b->verts[h->facet_vert[k > k0 ? k - 1 : k1 - 1]], p);
            pd_vec3 e2 = v3_sub(b->verts[h->facet_vert[k + 1 < k1 ? k + 1 : k0]], p);
            pd_vec3 n = v3_cross(e1, e2);
            double nn = v3_norm(n);
            /* The corners after next up to before prev. */
            for (int j = 2; j < k1 - k0 - 1 && !b->polish[v]; j++) {
                int m = k + j < k1 ? k + j : k + j - (k1 - k0);
                pd_vec3 r = v3_sub(b->verts[h->facet_vert[m]], p);
                double ca = v3_dot(v3_cross(r, e2), n), cb = v3_dot(v3_cross(e1, r), n);
                b->polish[v] = !(ca >= 0.0 && cb >= 0.0 && fabs(v3_dot(r, n)) <= tau * nn);
            }
        }
    }
}

void pd_body_free(pd_body *body)
{
    if (!body)
        return;
    free(body->verts);
    free(body->adj_start);
    free(body->adj);
    free(body->vf_start);
    free(body->vf);
    free(body->polish);
    free(body);
}

pd_status pd_body_build(const pd_part *part, pd_body **body, pd_diag *diag)
{
    if (!part || !body || !part->hull)
        return pd_fail(diag, PD_ERR_USAGE, "pd_body_build: NULL argument");
    const pd_hull *h = part->hull;
    double I[3][3], mass;
    if (part->mass_known) {
        /* Parallel-axis theorem moves the tensor from the mesh's own centre
         * to the centre used (they differ only when it was given). */
        pd_vec3 d = v3_sub(part->com, part->mass.com);
        double dd[3] = {d.x, d.y, d.z}, d2 = v3_dot(d, d);
        mass = part->mass.volume;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                I[i][j] = part->mass.inertia[i][j] + mass * ((i == j ? d2 : 0.0) - dd[i] * dd[j]);
    } else {
        double S[3][3];
        pd_hull_moments(h, part->com, &mass, S);
        double tr = S[0][0] + S[1][1] + S[2][2];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                I[i][j] = (i == j ? tr : 0.0) - S[i][j];
    }
    double eval[3], V[3][3];
    pd_sym_eigen3(CONST_M3(I), eval, V);
    if (!(mass > 0.0) || !(eval[0] > 0.0) || !isfinite(eval[2]))
        return pd_fail(diag, PD_ERR_COPLANAR,
                       "mass properties are degenerate: mass %.3g, principal moments %.3g, %.3g, %.3g",
                       mass, eval[0], eval[1], eval[2]);
    /* Snap moments equal within tolerance to their mean, so the flight takes
     * the exact symmetric branches (see PD_TOL_INERTIA_SYM_REL). */
    double tol = PD_TOL_INERTIA_SYM_REL * eval[2];
    if (eval[2] - eval[0] <= tol) {
        double m = (eval[0] + eval[1] + eval[2]) / 3.0;
        eval[0] = eval[1] = eval[2] = m;
    } else if (eval[1] - eval[0] <= tol) {
        eval[0] = eval[1] = 0.5 * (eval[0] + eval[1]);
    } else if (eval[2] - eval[1] <= tol) {
        eval[1] = eval[2] = 0.5 * (eval[1] + eval[2]);
    }

    pd_body *b = calloc(1, sizeof *b);
    if (!b)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory building the body");
    b->mass = mass;
    for (int i = 0; i < 3; i++) {
        b->moment[i] = eval[i];
        b->inv_moment[i] = 1.0 / eval[i];
    }
    /* Euler's equations: |dw_i/dt| = |I_j - I_k| / I_i |w_j w_k|. The ratios
     * are at most 1 (each moment is at most the sum of the other two) and
     * sum over j < k of w_j^2 w_k^2 is at most |w|^4 / 3, so |dw/dt| is at
     * most the largest ratio times |w|^2 / sqrt(3): 0 for a cube, whose
     * spin never changes. */
    double kappa = 0.0;
    for (int i = 0; i < 3; i++) {
        b->euler[i] = (eval[(i + 1) % 3] - eval[(i + 2) % 3]) / eval[i];
        kappa = fmax(kappa, fabs(b->euler[i]));
    }
    b->spin_accel = kappa / sqrt(3.0);
    b->frame = quat_from_matrix(CONST_M3(V));
    b->com = part->com;
    b->size = part->size;
    b->nverts = h->nverts;
    b->facet_start = h->facet_start;
    b->facet_vert = h->facet_vert;
    b->verts = malloc(sizeof *b->verts * (size_t)h->nverts);
    b->polish = calloc((size_t)h->nverts, sizeof *b->polish);
    if (!b->verts || !b->polish || build_adjacency(b, h) != PD_OK) {
        pd_body_free(b);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory building the body");
    }
    for (int i = 0; i < h->nverts; i++) {
        /* V^T (p - com): the exact matrix, not the quaternion, so the vertices
         * carry no extra round-off from the conversion. */
        pd_vec3 p = v3_sub(h->verts[i], part->com);
        b->verts[i] = v3(V[0][0] * p.x + V[1][0] * p.y + V[2][0] * p.z,
                         V[0][1] * p.x + V[1][1] * p.y + V[2][1] * p.z,
                         V[0][2] * p.x + V[1][2] * p.y + V[2][2] * p.z);
        double r = v3_norm(b->verts[i]);
        if (r > b->rmax)
            b->rmax = r;
    }
    mark_polish(b, h);
    *body = b;
    return PD_OK;
}

int pd_body_support(const pd_body *b, pd_vec3 dir, int start)
{
    int best = start >= 0 && start < b->nverts ? start : 0;
    double val = v3_dot(dir, b->verts[best]);
    /* Steepest descent over edge neighbours; on a convex polytope a vertex no
     * neighbour improves is the global minimum of a linear function (the
     * simplex method's argument). Strict improvement guarantees termination. */
    for (;;) {
        int next = best;
        for (int k = b->adj_start[best]; k < b->adj_start[best + 1]; k++) {
            double d = v3_dot(dir, b->verts[b->adj[k]]);
            if (d < val) {
                val = d;
                next = b->adj[k];
            }
        }
        if (next == best) {
            /* Polish: the corners of the facets around the minimum. A merged
             * facet may be bent by up to PD_TOL_PLANE_REL, which can hide a
             * lower corner behind a non-edge diagonal; where the facets
             * around it are flat that cannot happen (mark_polish). */
            if (!b->polish[best])
                return best;
            for (int k = b->vf_start[best]; k < b->vf_start[best + 1]; k++) {
                int f = b->vf[k];
                for (int m = b->facet_start[f]; m < b->facet_start[f + 1]; m++) {
                    double d = v3_dot(dir, b->verts[b->facet_vert[m]]);
                    if (d < val) {
                        val = d;
                        next = b->facet_vert[m];
                    }
                }
            }
            if (next == best)
                return best;
        }
        best = next;
    }
}

int pd_body_support_scan(const pd_body *b, pd_vec3 dir)
{
    int best = 0;
    double val = v3_dot(dir, b->verts[0]);
    for (int i = 1; i < b->nverts; i++) {
        double d = v3_dot(dir, b->verts[i]);
        if (d < val) {
            val = d;
            best = i;
        }
    }
    return best;
}
