/* part.c: building the immutable part model from a mesh (see posedrop/part.h).
 *
 * Order matters for the messages a user sees: the hull comes right after
 * welding because it classifies degenerate geometry most precisely (too few,
 * co-located, collinear, coplanar points); closedness and orientation come
 * next, then mass properties, then the centre of mass is checked against the
 * hull. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "base/fail.h"
#include "base/hash.h"
#include "base/mat3.h"
#include "base/size_range.h"
#include "hull/hull_internal.h"
#include "hull/hull_mass.h"
#include "mesh/mesh_internal.h"
#include "posedrop/part.h"
#include "posedrop/tolerances.h"
#include "part/part_check.h"
#include "part/part_tol.h"
#include "base/vec3.h"

void pd_part_options_default(pd_part_options *options)
{
    if (!options)
        return;
    options->com_given = 0;
    options->com = v3(0.0, 0.0, 0.0);
    options->cancel = NULL;
    options->stage = NULL;
    options->stage_user = NULL;
}

/* 1 when the caller asked to stop; otherwise says which stage starts. */
static int next_stage(const pd_part_options *opt, const char *name)
{
    if (opt->cancel && atomic_load(opt->cancel))
        return 1;
    if (opt->stage)
        opt->stage(opt->stage_user, name);
    return 0;
}

void pd_part_free(pd_part *part)
{
    if (!part)
        return;
    pd_mesh_free(part->mesh);
    pd_hull_free(part->hull);
    free(part);
}

/* The centre of mass must lie strictly inside every facet plane, or the part
 * would balance on a facet through its own centre and no pose is defined. */
static pd_status check_com_inside(const pd_part *p, pd_diag *diag)
{
    const pd_hull *h = p->hull;
    double tol = PD_TOL_COM_INSIDE_REL * p->size;
    int worst = 0;
    double worst_gap = 0.0;
    for (int f = 0; f < h->nfacets; f++) {
        double gap = h->offset[f] - v3_dot(h->normal[f], p->com);
        if (f == 0 || gap < worst_gap) {
            worst_gap = gap;
            worst = f;
        }
    }
    if (worst_gap > tol)
        return PD_OK;
    pd_vec3 n = h->normal[worst], c = v3_add(p->com, p->origin);
    if (worst_gap >= -tol)
        return pd_fail(diag, PD_ERR_COM_OUTSIDE,
                       "centre of mass (%.9g, %.9g, %.9g) m lies on the convex hull (%.3g m "
                       "from the plane of the facet with normal %.6g, %.6g, %.6g, within the "
                       "tolerance %.3g m, %g of the part's size): no pose can rest on it",
                       c.x, c.y, c.z, fabs(worst_gap), n.x, n.y, n.z, tol, PD_TOL_COM_INSIDE_REL);
    return pd_fail(diag, PD_ERR_COM_OUTSIDE,
                   "centre of mass (%.9g, %.9g, %.9g) m lies outside the convex hull, %.3g m "
                   "beyond the facet with normal %.6g, %.6g, %.6g",
                   c.x, c.y, c.z, -worst_gap, n.x, n.y, n.z);
}

/* The smallest eigenvalue of a symmetric matrix, and its largest in *top. */
static double eig_min(const double A[3][3], double *top)
{
    double e[3], V[3][3];
    pd_sym_eigen3(A, e, V);
    *top = e[2];
    return e[0];
}

/* What the drops need of a closed mesh's mass properties, checked once here
 * so that a part the static estimate accepts is one the drops accept: a
 * positive volume no larger than the hull's, principal moments positive,
 * second moments positive along every direction and within the hull's
 * (PD_TOL_INERTIA_REL, PD_TOL_SOLID_SHELL_REL). A surface that passes through
 * itself counts the volume on the far side of the fold negatively (or twice),
 * which no solid does. st is pd_mass_compute's status: no volume, when the
 * hull has some, is shells cancelling, not a flat part. */
static pd_status check_solid(const pd_part *p, pd_status st, pd_diag *diag)
{
    const char *why = "the mesh does not bound a solid: its surface passes through itself or "
                      "part of it is inside out";
    if (st == PD_ERR_COPLANAR) {
        return pd_fail(diag, PD_ERR_ORIENTATION, "%s, or its shells overlap (one taken as a "
                       "void inside another it crosses): it encloses no volume, though its "
                       "convex hull holds %.3g m^3", why, p->hull->volume);
    }
    if (st != PD_OK)
        return st;
    const pd_mass *m = &p->mass;
    double I[3][3], S[3][3], H[3][3], D[3][3];
    double tr = m->inertia[0][0] + m->inertia[1][1] + m->inertia[2][2];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            I[i][j] = m->inertia[i][j];
            S[i][j] = (i == j ? 0.5 * tr : 0.0) - I[i][j];
        }
    double i_top, i_min = eig_min(CONST_M3(I), &i_top);
    double s_top, s_min = eig_min(CONST_M3(S), &s_top);
    if (!(s_min >= -PD_TOL_INERTIA_REL * s_top))
        return pd_fail(diag, PD_ERR_ORIENTATION,
                       "%s (second moments from %.3g to %.3g m^5 per unit density, principal "
                       "moments of inertia from %.3g to %.3g m^5: a solid's are positive)",
                       why, s_min, s_top, i_min, i_top);
    if (!(i_min > PD_TOL_INERTIA_REL * i_top))
        return pd_fail(diag, PD_ERR_COLLINEAR,
                       "the part is too thin for its mass properties to be resolved: its "
                       "smallest principal moment of inertia is %.3g of its largest, below %g "
                       "(a rod of radius below %.2g of its length)", i_min / i_top,
                       PD_TOL_INERTIA_REL, sqrt(PD_TOL_INERTIA_REL / 6.0));
    /* The hull's, about the mesh's centre of mass. */
    double hv, R2 = 0.0, area = 0.0;
    pd_hull_moments(p->hull, m->com, &hv, H);
    const pd_hull *h = p->hull;
    for (int v = 0; v < h->nverts; v++) {
        pd_vec3 d = v3_sub(h->verts[v], m->com);
        R2 = fmax(R2, v3_dot(d, d));
    }
    for (int f = 0; f < h->nfacets; f++) {
        int k0 = h->facet_start[f], k1 = h->facet_start[f + 1];
        pd_vec3 a = h->verts[h->facet_vert[k0]];
        for (int k = k0 + 1; k + 1 < k1; k++)
            area += 0.5 * v3_norm(v3_cross(v3_sub(h->verts[h->facet_vert[k]], a),
                                           v3_sub(h->verts[h->facet_vert[k + 1]], a)));
    }
    double shell = PD_TOL_SOLID_SHELL_REL * p->size * area;
    if (m->volume > hv + shell)
        return pd_fail(diag, PD_ERR_ORIENTATION,
                       "%s, or its shells overlap (it encloses %.6g m^3, more than its convex "
                       "hull's %.6g m^3)", why, m->volume, hv);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            D[i][j] = H[i][j] - S[i][j];
    double d_top, d_min = eig_min(CONST_M3(D), &d_top), h_top;
    eig_min(CONST_M3(H), &h_top);
    if (d_min < -(shell * R2 + PD_TOL_INERTIA_REL * h_top))
        return pd_fail(diag, PD_ERR_ORIENTATION,
                       "%s, or its shells overlap (its second moment along one direction exceeds "
                       "its convex hull's by %.3g m^5, of %.3g m^5)", why, -d_min, h_top);
    return PD_OK;
}

/* A surface that crosses itself bounds no solid, though the overlap may
 * leave the moments within the hull's (two cubes offset along a diagonal
 * count their common part twice): refused, naming the two triangles (of the
 * welded mesh) and a point of their crossing in the file's frame. */
static pd_status check_no_crossing(const pd_part *p, pd_cancel_flag *cancel, pd_diag *diag)
{
    int ta, tb;
    pd_vec3 at;
    pd_status st = pd_mesh_self_crossing(p->mesh, cancel, &ta, &tb, &at, NULL);
    if (st != PD_OK)
        return st;
    if (ta < 0)
        return PD_OK;
    at = v3_add(at, p->origin);
    return pd_fail(diag, PD_ERR_ORIENTATION,
                   "the mesh does not bound a solid: its surface passes through itself "
                   "(triangles %d and %d of the welded mesh, counted from 0, cross at "
                   "(%.9g, %.9g, %.9g) m)", ta, tb, at.x, at.y, at.z);
}

/* The part's origin: the centre of the bounding box [lo, hi] rounded to a
 * multiple of u, the least power of two above the size L (L < u <= 2 L).
 * Positions relative to it are within 1.5 L per axis, so everything computed
 * from them carries round-off relative to L; the move itself rounds by at
 * most half an ulp of 1.5 L, and not at all on an axis where the origin is 3 L
 * or more from the file's (Sterbenz: v and o within a factor 2). Rounding to
 * u, rather than taking the centre itself, keeps a part that lies within
 * about its size of the file's origin where it is (origin 0: the same bits
 * as without the move). */
static pd_vec3 part_origin(pd_vec3 lo, pd_vec3 hi, double L)
{
    double u = ldexp(1.0, ilogb(L) + 1), c[3] = {lo.x, lo.y, lo.z}, d[3] = {hi.x, hi.y, hi.z};
    for (int i = 0; i < 3; i++)
        c[i] = u * floor((c[i] + 0.5 * (d[i] - c[i])) / u + 0.5);
    return v3(c[0], c[1], c[2]);
}

/* A part thinner than the weld tolerance loses its distinct vertices to
 * welding, and the hull's refusal (too few points, or flat) would describe
 * what was left rather than what was given: say what welding did. */
static pd_status weld_explains(pd_status st, int nbefore, int nafter, double size, pd_diag *diag)
{
    if (nafter == nbefore || !diag ||
        (st != PD_ERR_TOO_FEW_POINTS && st != PD_ERR_COLOCATED && st != PD_ERR_COLLINEAR &&
         st != PD_ERR_COPLANAR))
        return st;
    char hull[PD_DIAG_MESSAGE_LEN];
    snprintf(hull, sizeof hull, "%s", diag->message);
    return pd_fail(diag, st,
                   "welding vertices closer than %.3g m (%g of the part's size %.3g m) left "
                   "%d of its %d vertices on faces with area: the part is thinner than that (%s)",
                   PD_TOL_WELD_REL * size, PD_TOL_WELD_REL, size, nafter, nbefore, hull);
}

static pd_status build(pd_part *p, const pd_part_options *opt, pd_diag *diag)
{
    /* Every size-relative tolerance below needs a finite size (the
     * coordinates were checked finite), within the range where products of
     * the part's lengths stay normal doubles. */
    pd_mesh *m = p->mesh;
    pd_vec3 lo = v3(0.0, 0.0, 0.0), hi = lo;
    for (int i = 0; i < m->nverts; i++) {
        pd_vec3 v = m->verts[i];
        lo = i == 0 ? v : v3_min(lo, v);
        hi = i == 0 ? v : v3_max(hi, v);
    }
    pd_status st = pd_size_check(lo, hi, "", diag);
    if (st != PD_OK)
        return st;
    p->size = pd_mesh_size(m);
    if (p->size > 0.0) {
        p->origin = part_origin(lo, hi, p->size);
        /* The move keeps the digits the file has; it cannot restore those a
         * far-off placement already rounded away. */
        double far = fmax(fmax(fmax(fabs(lo.x), fabs(hi.x)), fmax(fabs(lo.y), fabs(hi.y))),
                          fmax(fabs(lo.z), fabs(hi.z)));
        double step = far * DBL_EPSILON;
        if (step > PD_TOL_PLANE_REL * p->size)
            pd_warn(diag, "coordinates reach %.3g m from the file's origin, so they are rounded "
                          "in steps of up to %.3g m, %.2g of the part's size %.3g m (more than "
                          "the plane tolerance %.0e): the part is taken as the rounded points",
                    far, step, step / p->size, p->size, PD_TOL_PLANE_REL);
        for (int i = 0; i < m->nverts; i++)
            m->verts[i] = v3_sub(m->verts[i], p->origin);
    }
    pd_vec3 com_given = v3_sub(opt->com, p->origin);
    int nbefore = m->nverts;
    double size0 = p->size;
    if (next_stage(opt, "welding"))
        return PD_ERR_CANCELLED;
    st = pd_mesh_weld_cancel(p->mesh, PD_TOL_WELD_REL * p->size, NULL, opt->cancel);
    if (st != PD_OK)
        return st == PD_ERR_CANCELLED ? st : PD_ERR_NOMEM;
    p->size = pd_mesh_size(p->mesh);
    if (next_stage(opt, "convex hull"))
        return PD_ERR_CANCELLED;
    st = pd_hull_build_cancel(p->mesh->verts, p->mesh->nverts, opt->cancel, &p->hull, diag);
    if (st == PD_ERR_CANCELLED)
        return st;
    if (st != PD_OK)
        return weld_explains(st, nbefore, p->mesh->nverts, size0, diag);

    int flipped = 0;
    if (next_stage(opt, "orienting"))
        return PD_ERR_CANCELLED;
    st = pd_mesh_orient_cancel(p->mesh, &flipped, opt->cancel, diag);
    if (st == PD_ERR_CANCELLED || st == PD_ERR_NOMEM)
        return st;
    if (st == PD_OK) {
        p->closed = 1;
        if (flipped > 0)
            pd_warn(diag, "%d of %d faces were oriented inconsistently with their neighbours "
                          "and have been flipped", flipped, p->mesh->ntris);
    } else if ((st == PD_ERR_NOT_CLOSED || st == PD_ERR_ORIENTATION) && opt->com_given) {
        /* Only the hull and the centre of mass matter to the static
         * estimators, so a given centre of mass makes an open mesh usable. */
        pd_warn(diag, "%s; its mass properties are unknown, the given centre of mass is used",
                diag ? diag->message : "mesh not closed");
        if (diag)
            diag->message[0] = '\0';
    } else {
        return st;
    }

    if (p->closed) {
        if (next_stage(opt, "mass properties"))
            return PD_ERR_CANCELLED;
        st = check_solid(p, pd_mass_compute(p->mesh, &p->mass, diag), diag);
        if (st == PD_OK)
            st = next_stage(opt, "self-crossing check") ? PD_ERR_CANCELLED
                                                         : check_no_crossing(p, opt->cancel, diag);
        if (st == PD_ERR_NOMEM || st == PD_ERR_CANCELLED)
            return st;
        if (st == PD_OK)
            p->mass_known = 1;
        else if (!opt->com_given)
            return st;
        else if (diag) {
            /* As for an open mesh: the hull and the given centre are all
             * the estimators need, and the drops take the hull's inertia. */
            pd_warn(diag, "%s; the given centre of mass and the convex hull's inertia are used",
                    diag->message);
            diag->message[0] = '\0';
        }
    }
    p->com = opt->com_given ? com_given : p->mass.com;
    if (!v3_isfinite(p->com))
        return pd_fail(diag, PD_ERR_NONFINITE, "centre of mass is not finite");
    return check_com_inside(p, diag);
}

/* The build of pd_part_build and pd_part_build_take: mesh is the caller's
 * (copied) or, when owned is not NULL, *owned, taken over and set NULL
 * whatever the outcome. */
static pd_status part_build(const pd_mesh *mesh, pd_mesh **owned, const pd_part_options *options,
                            pd_part **part, pd_diag *diag, const char *who)
{
    pd_part_options opt;
    if (options)
        opt = *options;
    else
        pd_part_options_default(&opt);
    pd_mesh *take = owned ? *owned : NULL;
    if (owned)
        *owned = NULL;
    pd_status st = PD_OK;
    if (!mesh || !part)
        st = pd_fail(diag, PD_ERR_USAGE, "%s: NULL %s", who, mesh ? "part" : "mesh");
    /* A mesh made by hand gets an input error, not an out-of-memory from
     * copying a negative count or a crash from an index off its end. */
    if (st == PD_OK)
        st = pd_mesh_validate(mesh, who, diag);
    if (st == PD_OK && opt.com_given != 0 && opt.com_given != 1)
        st = pd_fail(diag, PD_ERR_USAGE, "%s: option com_given is %d: expected 0 or 1", who,
                     opt.com_given);
    if (st == PD_OK && opt.com_given && !v3_isfinite(opt.com))
        st = pd_fail(diag, PD_ERR_NONFINITE, "%s: the given centre of mass is not finite", who);
    pd_part *p = st == PD_OK ? calloc(1, sizeof *p) : NULL;
    if (st == PD_OK && (!p || !(p->mesh = take ? take : pd_mesh_clone(mesh)))) {
        free(p);
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory copying the mesh");
    }
    if (st != PD_OK) {
        pd_mesh_free(take);
        return st;
    }
    st = build(p, &opt, diag);
    if (st != PD_OK) {
        if (st == PD_ERR_NOMEM)
            pd_fail(diag, st, "out of memory building the part");
        if (st == PD_ERR_CANCELLED)
            pd_fail(diag, st, "building the part cancelled");
        pd_part_free(p);
        return st;
    }
    *part = p;
    return PD_OK;
}

pd_status pd_part_build(const pd_mesh *mesh, const pd_part_options *options, pd_part **part,
                        pd_diag *diag)
{
    return part_build(mesh, NULL, options, part, diag, "pd_part_build");
}

pd_status pd_part_build_take(pd_mesh **mesh, const pd_part_options *options, pd_part **part,
                             pd_diag *diag)
{
    if (!mesh)
        return pd_fail(diag, PD_ERR_USAGE, "pd_part_build_take: NULL mesh");
    return part_build(*mesh, mesh, options, part, diag, "pd_part_build_take");
}

pd_status pd_part_check(const pd_part *part, const char *who, pd_diag *diag)
{
    if (!part)
        return pd_fail(diag, PD_ERR_USAGE, "%s: NULL part", who);
    const pd_hull *h = part->hull;
    if (!part->mesh || !h || h->nfacets < 4 || h->nverts < 4 || !h->verts || !h->normal ||
        !h->offset || !h->facet_start || !h->facet_vert || !h->facet_adj || !(part->size > 0.0))
        return pd_fail(diag, PD_ERR_USAGE, "%s: the part is not one pd_part_build made (its "
                       "mesh or hull is missing)", who);
    return PD_OK;
}

static void hash_vec3s(pd_hash *s, const pd_vec3 *v, int n)
{
    for (int i = 0; i < n; i++) {
        double x[3] = {v[i].x, v[i].y, v[i].z};
        pd_hash_doubles(s, x, 3);
    }
}

uint64_t pd_part_fingerprint(const pd_part *p)
{
    const pd_hull *h = p->hull;
    pd_hash s;
    pd_hash_init(&s, 0x70617274); /* "part" */
    pd_hash_doubles(&s, &p->size, 1);
    hash_vec3s(&s, &p->com, 1);
    int counts[4] = {p->mass_known, h->nverts, h->nfacets, h->facet_start[h->nfacets]};
    pd_hash_ints(&s, counts, 4);
    if (p->mass_known) {
        pd_hash_doubles(&s, &p->mass.volume, 1);
        hash_vec3s(&s, &p->mass.com, 1);
        for (int i = 0; i < 3; i++)
            pd_hash_doubles(&s, p->mass.inertia[i], 3);
    }
    hash_vec3s(&s, h->verts, h->nverts);
    pd_hash_ints(&s, h->facet_start, (long)h->nfacets + 1);
    pd_hash_ints(&s, h->facet_vert, h->facet_start[h->nfacets]);
    hash_vec3s(&s, h->normal, h->nfacets);
    pd_hash_doubles(&s, h->offset, h->nfacets);
    return s.h;
}
