/* static.c: the QS and PQS estimators end to end (see posedrop/static.h):
 * classify facets, raw solid-angle probabilities, quasi-static graph, PQS
 * bands, propagation to stable facets, and the table of stable poses. */
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "part/part_check.h"
#include "posedrop/tolerances.h"
#include "static/static_check.h"
#include "static/static_tol.h"
#include "static/static_internal.h"
#include "base/vec3.h"

void pd_static_options_default(pd_static_options *options)
{
    if (!options)
        return;
    options->topple = PD_TOPPLE_DESCENT;
    options->epsilon = 20.0 * M_PI / 180.0;
    options->compare = PD_PQS_COMPARE_RAW;
    options->band = PD_PQS_BAND_RECT;
    options->cancel = NULL;
}

static int cancelled(const pd_static_options *opt)
{
    return opt->cancel && atomic_load(opt->cancel);
}

pd_status pd_static_options_check(const pd_static_options *o, pd_diag *diag)
{
    if (!o)
        return pd_fail(diag, PD_ERR_USAGE, "pd_static_options_check: NULL options");
    if ((unsigned)o->topple > (unsigned)PD_TOPPLE_EDGE)
        return pd_fail(diag, PD_ERR_USAGE, "option topple is %d: expected PD_TOPPLE_DESCENT or "
                       "PD_TOPPLE_EDGE", (int)o->topple);
    if (!(o->epsilon >= 0.0 && o->epsilon <= 0.5 * M_PI))
        return pd_fail(diag, PD_ERR_USAGE, "option epsilon is %g degrees: expected a PQS "
                       "angle from 0 to 90 degrees", o->epsilon * 180.0 / M_PI);
    if ((unsigned)o->compare > (unsigned)PD_PQS_COMPARE_QS)
        return pd_fail(diag, PD_ERR_USAGE, "option compare is %d: expected PD_PQS_COMPARE_RAW "
                       "or PD_PQS_COMPARE_QS", (int)o->compare);
    if ((unsigned)o->band > (unsigned)PD_PQS_BAND_EXACT)
        return pd_fail(diag, PD_ERR_USAGE, "option band is %d: expected PD_PQS_BAND_RECT or "
                       "PD_PQS_BAND_EXACT", (int)o->band);
    return PD_OK;
}

void pd_static_result_free(pd_static_result *result)
{
    if (!result)
        return;
    free(result->facets);
    free(result->poses);
    free(result);
}

/* Orders unit normals lexicographically, components equal within
 * PD_TOL_NORMAL_TIE (round-off must not decide the order of poses). */
static int normal_cmp(pd_vec3 a, pd_vec3 b)
{
    double da[3] = {a.x, a.y, a.z}, db[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; i++)
        if (fabs(da[i] - db[i]) > PD_TOL_NORMAL_TIE)
            return da[i] < db[i] ? -1 : 1;
    return 0;
}

static int cmp_p_qs_desc(const void *pa, const void *pb)
{
    const pd_pose *a = pa, *b = pb;
    if (a->p_qs != b->p_qs)
        return a->p_qs > b->p_qs ? -1 : 1;
    return a->facet - b->facet;
}

static int cmp_normal(const void *pa, const void *pb)
{
    const pd_pose *a = pa, *b = pb;
    int c = normal_cmp(a->normal, b->normal);
    return c ? c : a->facet - b->facet;
}

/* By descending p_qs; a run of poses whose p_qs tie with the run's first
 * (relative PD_TOL_PROB_TIE_REL) is then ordered by normal. Sorting exactly
 * first and grouping after keeps the comparison a strict order. */
static void sort_poses(pd_pose *poses, int n)
{
    qsort(poses, (size_t)n, sizeof *poses, cmp_p_qs_desc);
    for (int i = 0; i < n;) {
        int j = i + 1;
        while (j < n && poses[i].p_qs - poses[j].p_qs <= PD_TOL_PROB_TIE_REL * poses[i].p_qs)
            j++;
        qsort(poses + i, (size_t)(j - i), sizeof *poses, cmp_normal);
        i = j;
    }
}

static void warn_knives(const pd_hull *hull, const pd_static_result *res, pd_diag *diag)
{
    for (int f = 0; f < res->nfacets; f++)
        if (res->facets[f].knife) {
            pd_vec3 n = hull->normal[f];
            pd_warn(diag,
                    "facet %d (normal %.6g, %.6g, %.6g): the centre of mass projects onto its "
                    "boundary (knife edge); counted as unstable, it topples to facet %d",
                    f + 1, n.x, n.y, n.z, res->facets[f].next + 1);
        }
}

static pd_status estimate(const pd_part *part, const pd_static_options *opt,
                          pd_static_result *res, facet_geom *geom, double *pert, pd_diag *diag)
{
    const pd_hull *hull = part->hull;
    pd_facet_result *fr = res->facets;
    if (cancelled(opt))
        return PD_ERR_CANCELLED;
    for (int f = 0; f < hull->nfacets; f++) {
        pd_facet_classify(hull, part->com, f, &geom[f], &fr[f]);
        fr[f].solid_angle = pd_solid_angle_facet(hull, part->com, f, geom[f].nearest);
        fr[f].p_raw = fr[f].solid_angle / (4.0 * M_PI);
    }
    if (cancelled(opt))
        return PD_ERR_CANCELLED;
    pd_status st = pd_topple_graph(hull, part->com, geom, opt->topple, res, diag);
    if (st != PD_OK)
        return st;
    for (int f = 0; f < hull->nfacets; f++)
        res->nknife += fr[f].knife;
    warn_knives(hull, res, diag);
    for (int f = 0; f < hull->nfacets; f++)
        fr[fr[f].rest].p_qs += fr[f].p_raw;
    if (cancelled(opt))
        return PD_ERR_CANCELLED;
    st = pd_pqs_perturb(hull, part->com, geom, opt, res, pert, diag);
    if (st != PD_OK)
        return st;
    for (int f = 0; f < hull->nfacets; f++)
        fr[fr[f].rest].p_pqs += pert[f];

    for (int f = 0; f < hull->nfacets; f++)
        res->nposes += fr[f].stable;
    res->poses = malloc(sizeof *res->poses * (size_t)(res->nposes > 0 ? res->nposes : 1));
    if (!res->poses)
        return PD_ERR_NOMEM;
    int k = 0;
    for (int f = 0; f < hull->nfacets; f++)
        if (fr[f].stable) {
            pd_pose *p = &res->poses[k++];
            p->facet = f;
            p->normal = hull->normal[f];
            p->area = fr[f].area;
            p->height = fr[f].height;
            p->p_qs = fr[f].p_qs;
            p->p_pqs = fr[f].p_pqs;
        }
    sort_poses(res->poses, res->nposes);
    return PD_OK;
}

pd_status pd_static_estimate(const pd_part *part, const pd_static_options *options,
                             pd_static_result **result, pd_diag *diag)
{
    pd_static_options opt;
    if (options)
        opt = *options;
    else
        pd_static_options_default(&opt);
    pd_status st = pd_part_check(part, "pd_static_estimate", diag);
    if (st != PD_OK)
        return st;
    if (!result)
        return pd_fail(diag, PD_ERR_USAGE, "pd_static_estimate: NULL result");
    if ((st = pd_static_options_check(&opt, diag)) != PD_OK)
        return st;

    int n = part->hull->nfacets;
    pd_static_result *res = calloc(1, sizeof *res);
    facet_geom *geom = malloc(sizeof *geom * (size_t)n);
    double *pert = malloc(sizeof *pert * (size_t)n);
    st = PD_ERR_NOMEM;
    if (res && geom && pert) {
        res->part_fingerprint = pd_part_fingerprint(part);
        res->nfacets = n;
        res->facets = calloc((size_t)n, sizeof *res->facets);
        if (res->facets)
            st = estimate(part, &opt, res, geom, pert, diag);
    }
    free(geom);
    free(pert);
    if (st != PD_OK) {
        if (st == PD_ERR_NOMEM)
            pd_fail(diag, st, "out of memory in the static estimators (%d facets)", n);
        if (st == PD_ERR_CANCELLED)
            pd_fail(diag, st, "the static estimate cancelled");
        pd_static_result_free(res);
        return st;
    }
    *result = res;
    return PD_OK;
}

pd_status pd_static_result_check(const pd_part *part, const pd_static_result *res,
                                 const char *who, pd_diag *diag)
{
    pd_status st = pd_part_check(part, who, diag);
    if (st != PD_OK)
        return st;
    if (!res)
        return pd_fail(diag, PD_ERR_USAGE, "%s: NULL static result", who);
    if (res->part_fingerprint != pd_part_fingerprint(part))
        return pd_fail(diag, PD_ERR_USAGE, "%s: the static result was computed for another "
                       "part, or the part changed since", who);
    const pd_hull *h = part->hull;
    if (res->nfacets != h->nfacets || !res->facets || res->nposes < 0 ||
        res->nposes > h->nfacets || (res->nposes > 0 && !res->poses))
        return pd_fail(diag, PD_ERR_USAGE, "%s: the static result's tables (%d facets, %d "
                       "poses) do not fit the part's hull of %d facets", who, res->nfacets,
                       res->nposes, h->nfacets);
    /* Poses on distinct facets in range: a facet may hold one pose only,
     * so each pose's facet must not recur among the poses after it; the
     * facets' rest links record each stable facet as its own. */
    for (int i = 0; i < res->nposes; i++) {
        int f = res->poses[i].facet;
        if (f < 0 || f >= h->nfacets || res->facets[f].rest != f)
            return pd_fail(diag, PD_ERR_USAGE, "%s: pose %d of the static result rests on "
                           "facet %d, not a stable facet of the part's hull (%d facets)", who,
                           i + 1, f, h->nfacets);
        for (int j = 0; j < i; j++)
            if (res->poses[j].facet == f)
                return pd_fail(diag, PD_ERR_USAGE, "%s: poses %d and %d of the static result "
                               "rest on the same facet %d", who, j + 1, i + 1, f);
    }
    return PD_OK;
}
