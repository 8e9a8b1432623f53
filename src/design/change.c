/* change.c: the family of parts a list of changes spans (posedrop/design.h).
 *
 * Every change moves each mesh vertex by an amount linear in its value,
 * computed from the vertex's place in the part as given: a stretch of
 * factor s along axis e over the slab [A, B] moves x by
 *     (s - 1) ov(e . x) e,
 * ov(u) the signed length of the part of [A, B] between the anchor's
 * coordinate u0 (the centre of mass as given) and u. The map is then exact
 * (the slab stretched, the rest carried rigidly) and its motion per unit of
 * value, ov(u) e, does not depend on the value, which keeps the derivatives
 * of design.c and sensitivity.c simple. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/mat3.h"
#include "base/vec3.h"
#include "design/design_internal.h"

/* An inertia tensor counts as diagonal in the file's axes when its
 * off-diagonal part is below this relative to its largest entry: round-off
 * of the mass integrals is ~1e-15 of it, a part turned by 1e-6 rad has
 * ~1e-6. */
#define PRINCIPAL_TOL 1e-9

static pd_vec3 col(double V[3][3], int j)
{
    return v3(V[0][j], V[1][j], V[2][j]);
}

pd_status pd_design_axes(const pd_part *part, pd_vec3 axes[3], pd_diag *diag)
{
    if (!part || !axes)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_axes: NULL argument");
    axes[0] = v3(1, 0, 0);
    axes[1] = v3(0, 1, 0);
    axes[2] = v3(0, 0, 1);
    if (!part->mass_known)
        return PD_OK;
    const double(*I)[3] = CONST_M3(part->mass.inertia);
    double big = 0.0, off = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            big = fmax(big, fabs(I[i][j]));
            if (i != j)
                off = fmax(off, fabs(I[i][j]));
        }
    if (off <= PRINCIPAL_TOL * big)
        return PD_OK;
    double ev[3], V[3][3];
    pd_sym_eigen3(I, ev, V);
    /* The permutation of eigenvectors onto file axes that keeps them nearest. */
    static const int perm[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    double best = -1.0;
    int bp = 0;
    for (int p = 0; p < 6; p++) {
        double score = 1.0;
        for (int i = 0; i < 3; i++)
            score *= fabs(V[i][perm[p][i]]);
        if (score > best) {
            best = score;
            bp = p;
        }
    }
    for (int i = 0; i < 3; i++) {
        pd_vec3 e = col(V, perm[bp][i]);
        double c = i == 0 ? e.x : i == 1 ? e.y : e.z;
        axes[i] = c < 0.0 ? v3_neg(e) : e;
    }
    return PD_OK;
}

double design_identity(const pd_change *c)
{
    return c->kind == PD_CHANGE_SCALE ? 1.0 : 0.0;
}

pd_status design_ctx_init(design_ctx *ctx, const pd_part *base, const pd_change *changes, int n,
                          pd_diag *diag)
{
    if (!base || !changes || n < 1 || n > PD_DESIGN_MAX_CHANGES)
        return pd_fail(diag, PD_ERR_USAGE, "design: expected 1 to %d changes and a part, got %d",
                       PD_DESIGN_MAX_CHANGES, n);
    memset(ctx, 0, sizeof *ctx);
    ctx->base = base;
    ctx->changes = changes;
    ctx->n = n;
    pd_design_axes(base, ctx->axes, diag);
    ctx->anchor = v3_add(base->com, base->origin);
    ctx->uniform = base->mass_known;
    ctx->delta0 = base->mass_known ? v3_sub(base->com, base->mass.com) : v3(0, 0, 0);
    for (int k = 0; k < n; k++) {
        const pd_change *c = &changes[k];
        if ((unsigned)c->kind > (unsigned)PD_CHANGE_COM || c->axis < 0 || c->axis > 2 ||
            (c->slab != 0 && c->slab != 1))
            return pd_fail(diag, PD_ERR_USAGE, "design: change %d has kind %d, axis %d, slab %d: "
                           "expected a scale or com change on axis 0, 1 or 2, slab 0 or 1", k + 1,
                           (int)c->kind, c->axis, c->slab);
        if (!(isfinite(c->lo) && isfinite(c->hi) && c->lo < c->hi) ||
            (c->kind == PD_CHANGE_SCALE && !(c->lo > 0.0)))
            return pd_fail(diag, PD_ERR_USAGE, "design: change %d's range %g:%g: expected lo < hi%s",
                           k + 1, c->lo, c->hi, c->kind == PD_CHANGE_SCALE ? ", lo > 0" : "");
        if (c->kind == PD_CHANGE_SCALE && c->slab) {
            if (!(isfinite(c->from) && isfinite(c->to) && c->from < c->to))
                return pd_fail(diag, PD_ERR_USAGE, "design: change %d's slab %g:%g m: expected "
                               "from < to", k + 1, c->from, c->to);
        }
        for (int j = 0; j < k; j++) {
            const pd_change *o = &changes[j];
            if (o->kind != c->kind || o->axis != c->axis)
                continue;
            int apart = c->kind == PD_CHANGE_SCALE && c->slab && o->slab &&
                        (c->to <= o->from || o->to <= c->from);
            if (!apart)
                return pd_fail(diag, PD_ERR_USAGE, "design: changes %d and %d both %s along axis "
                               "%d%s", j + 1, k + 1, c->kind == PD_CHANGE_SCALE ? "stretch" : "move "
                               "the centre of mass", c->axis, c->kind == PD_CHANGE_SCALE ?
                               " over overlapping spans" : "");
        }
        ctx->lo[k] = c->kind == PD_CHANGE_SCALE ? log(c->lo) : c->lo;
        ctx->hi[k] = c->kind == PD_CHANGE_SCALE ? log(c->hi) : c->hi;
    }
    return PD_OK;
}

/* The signed length of [A, B] between u0 and u (positive for u > u0). */
static double overlap(double u, double u0, double A, double B)
{
    if (u >= u0)
        return fmax(0.0, fmin(u, B) - fmax(u0, A));
    return -fmax(0.0, fmin(u0, B) - fmax(u, A));
}

/* Change k's motion of the point x (file frame) per unit of value. */
static pd_vec3 point_motion(const design_ctx *ctx, int k, pd_vec3 x)
{
    const pd_change *c = &ctx->changes[k];
    if (c->kind != PD_CHANGE_SCALE)
        return v3(0, 0, 0);
    pd_vec3 e = ctx->axes[c->axis];
    double A = c->slab ? c->from : -DBL_MAX, B = c->slab ? c->to : DBL_MAX;
    return v3_scale(e, overlap(v3_dot(e, x), v3_dot(e, ctx->anchor), A, B));
}

pd_status design_build(const design_ctx *ctx, const double *value, pd_part **out, pd_diag *diag)
{
    const pd_part *b = ctx->base;
    const pd_mesh *bm = b->mesh;
    pd_mesh m = {bm->nverts, malloc(sizeof(pd_vec3) * (size_t)bm->nverts), bm->ntris, bm->tris};
    if (!m.verts)
        return pd_fail(diag, PD_ERR_NOMEM, "design: out of memory for %d vertices", bm->nverts);
    pd_vec3 offset = ctx->delta0;
    int moved_com = v3_dot(offset, offset) > 0.0 || !ctx->uniform;
    for (int k = 0; k < ctx->n; k++) {
        if (!isfinite(value[k]) || (ctx->changes[k].kind == PD_CHANGE_SCALE && !(value[k] > 0.0))) {
            free(m.verts);
            return pd_fail(diag, PD_ERR_USAGE, "design: change %d's value %g is not %s", k + 1,
                           value[k], ctx->changes[k].kind == PD_CHANGE_SCALE ? "a factor above 0"
                                                                             : "finite");
        }
        if (ctx->changes[k].kind == PD_CHANGE_COM) {
            offset = v3_add(offset, v3_scale(ctx->axes[ctx->changes[k].axis], value[k]));
            moved_com = 1;
        }
    }
    for (int i = 0; i < bm->nverts; i++) {
        pd_vec3 x = v3_add(bm->verts[i], b->origin), y = x;
        for (int k = 0; k < ctx->n; k++)
            if (ctx->changes[k].kind == PD_CHANGE_SCALE)
                y = v3_add(y, v3_scale(point_motion(ctx, k, x), value[k] - 1.0));
        m.verts[i] = y;
    }
    pd_part_options opt;
    pd_part_options_default(&opt);
    pd_status st = PD_OK;
    if (moved_com) {
        opt.com_given = 1;
        if (ctx->uniform) {
            pd_mass mass;
            st = pd_mass_compute(&m, &mass, diag);
            opt.com = v3_add(mass.com, offset);
        } else {
            opt.com = v3_add(ctx->anchor, offset);
        }
    }
    if (st == PD_OK)
        st = pd_part_build(&m, &opt, out, diag);
    free(m.verts);
    if (st == PD_OK && (*out)->mesh->nverts != bm->nverts) {
        pd_part_free(*out);
        *out = NULL;
        return pd_fail(diag, PD_ERR_RANGE, "design: the change welds vertices of the part "
                       "together (it flattens the part to round-off)");
    }
    return st;
}

/* The motion of the material's centre of mass: com = M / V over the signed
 * tetrahedra (o, a, b, c) of the mesh's triangles, o fixed; V_t = a.(b x c)/6,
 * M_t = V_t (a + b + c) / 4, so dV_t and dM_t are linear in the corners'
 * motion, and dcom = (dM - com dV) / V. */
static pd_vec3 material_motion(const pd_part *part, const pd_vec3 *mv)
{
    const pd_mesh *m = part->mesh;
    pd_vec3 o = part->com;
    double V = 0.0, dV = 0.0;
    pd_vec3 M = v3(0, 0, 0), dM = v3(0, 0, 0);
    for (int t = 0; t < m->ntris; t++) {
        const int *tri = m->tris[t];
        pd_vec3 a = v3_sub(m->verts[tri[0]], o), b = v3_sub(m->verts[tri[1]], o),
                c = v3_sub(m->verts[tri[2]], o);
        pd_vec3 da = mv[tri[0]], db = mv[tri[1]], dc = mv[tri[2]];
        double vt = v3_dot(a, v3_cross(b, c)) / 6.0;
        double dvt = (v3_dot(da, v3_cross(b, c)) + v3_dot(db, v3_cross(c, a)) +
                      v3_dot(dc, v3_cross(a, b))) / 6.0;
        pd_vec3 s = v3_add(a, v3_add(b, c)), ds = v3_add(da, v3_add(db, dc));
        V += vt;
        dV += dvt;
        M = v3_add(M, v3_scale(s, vt / 4.0));
        dM = v3_add(dM, v3_add(v3_scale(s, dvt / 4.0), v3_scale(ds, vt / 4.0)));
    }
    pd_vec3 c = v3_scale(M, 1.0 / V);
    return v3_scale(v3_sub(dM, v3_scale(c, dV)), 1.0 / V);
}

void design_motion(const design_ctx *ctx, const pd_part *part, int k, pd_vec3 *dv, pd_vec3 *dcom)
{
    const pd_change *c = &ctx->changes[k];
    const pd_hull *h = part->hull;
    const pd_mesh *bm = ctx->base->mesh;
    if (c->kind == PD_CHANGE_COM) {
        for (int v = 0; v < h->nverts; v++)
            dv[v] = v3(0, 0, 0);
        *dcom = ctx->axes[c->axis];
        return;
    }
    /* Vertex i of part's mesh is vertex i of the base's (design_build
     * keeps the order). */
    int nm = part->mesh->nverts;
    pd_vec3 *mv = malloc(sizeof *mv * (size_t)nm);
    for (int v = 0; v < h->nverts; v++) {
        int i = h->vert_source[v];
        dv[v] = point_motion(ctx, k, v3_add(bm->verts[i], ctx->base->origin));
    }
    *dcom = v3(0, 0, 0);
    if (!mv)
        return;
    if (ctx->uniform) {
        for (int i = 0; i < nm; i++)
            mv[i] = point_motion(ctx, k, v3_add(bm->verts[i], ctx->base->origin));
        *dcom = material_motion(part, mv);
    }
    free(mv);
}

int design_match_facet(const pd_part *base, int f, const pd_part *part, int *mark)
{
    const pd_hull *bh = base->hull, *h = part->hull;
    for (int i = bh->facet_start[f]; i < bh->facet_start[f + 1]; i++)
        mark[bh->vert_source[bh->facet_vert[i]]] = 1;
    int best = -1, most = 2;
    for (int g = 0; g < h->nfacets; g++) {
        int shared = 0;
        for (int i = h->facet_start[g]; i < h->facet_start[g + 1]; i++)
            shared += mark[h->vert_source[h->facet_vert[i]]];
        if (shared > most) {
            most = shared;
            best = g;
        }
    }
    for (int i = bh->facet_start[f]; i < bh->facet_start[f + 1]; i++)
        mark[bh->vert_source[bh->facet_vert[i]]] = 0;
    return best;
}

int design_facet_by_normal(const pd_part *base, pd_vec3 n, double *angle)
{
    const pd_hull *h = base->hull;
    int best = -1;
    double ba = M_PI;
    for (int f = 0; f < h->nfacets; f++) {
        double a = v3_angle(h->normal[f], n);
        if (a < ba) {
            ba = a;
            best = f;
        }
    }
    if (angle)
        *angle = ba;
    return ba <= 5.0 * M_PI / 180.0 ? best : -1;
}

pd_status pd_design_apply(const pd_part *part, const pd_change *changes, int nchanges,
                          const double *value, pd_part **changed, pd_diag *diag)
{
    if (!part || !changes || !value || !changed)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_apply: NULL argument");
    design_ctx ctx;
    pd_status st = design_ctx_init(&ctx, part, changes, nchanges, diag);
    if (st != PD_OK)
        return st;
    *changed = NULL;
    return design_build(&ctx, value, changed, diag);
}
