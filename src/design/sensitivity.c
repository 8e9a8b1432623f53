/* sensitivity.c: what each change moves, per pose (posedrop/design.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/vec3.h"
#include "design/design_match.h"
#include "static/tangent.h"

/* The drops' half steps: a factor 1 +- 0.05 and an offset of 2% of the
 * part's size move the poses by a few points on the parts of
 * docs/design.md, large against the paired drops' noise and small against
 * the curvature of the response. */
#define STEP_FACTOR 0.05
#define STEP_OFFSET_REL 0.02

/* The one-sided difference quotients over this step tell a smooth point
 * from a kink of the static structure. */
#define KINK_STEP_FACTOR 1e-4

void pd_design_sens_free(pd_design_sens *s)
{
    if (!s)
        return;
    free(s->rows);
    free(s);
}

static int class_index(const int *class_of, int i)
{
    return class_of ? class_of[i] : i;
}

/* The part at value, its static estimate, and its poses' map onto the
 * base's (design_pose_map); on failure all three NULL. */
static pd_status changed_at(const design_ctx *ctx, const pd_static_result *bres,
                            const pd_static_options *opt, const double *value, pd_part **p,
                            pd_static_result **r, int **map, pd_diag *diag)
{
    *p = NULL;
    *r = NULL;
    *map = NULL;
    pd_status st = design_build(ctx, value, p, diag);
    if (st == PD_OK)
        st = pd_static_estimate(*p, opt, r, diag);
    if (st == PD_OK && !(*map = malloc(sizeof **map * (size_t)((*r)->nposes + 1))))
        st = PD_ERR_NOMEM;
    if (st == PD_OK)
        st = design_pose_map(ctx->base, bres, *p, *r, *map);
    if (st != PD_OK) {
        free(*map);
        pd_static_result_free(*r);
        pd_part_free(*p);
        *p = NULL;
        *r = NULL;
        *map = NULL;
    }
    return st;
}

/* The static probabilities of the part at value, summed into base poses
 * (classes): qs[c], pqs[c]. */
static pd_status static_at(const design_ctx *ctx, const pd_static_result *bres,
                           const pd_static_options *opt, const double *value,
                           const int *class_of, int nc, double *qs, double *pqs,
                           pd_diag *diag)
{
    pd_part *p;
    pd_static_result *r;
    int *map;
    pd_status st = changed_at(ctx, bres, opt, value, &p, &r, &map, diag);
    if (st != PD_OK)
        return st;
    for (int c = 0; c < nc; c++)
        qs[c] = pqs[c] = 0.0;
    for (int j = 0; j < r->nposes; j++)
        if (map[j] >= 0) {
            qs[class_index(class_of, map[j])] += r->poses[j].p_qs;
            pqs[class_index(class_of, map[j])] += r->poses[j].p_pqs;
        }
    free(map);
    pd_static_result_free(r);
    pd_part_free(p);
    return PD_OK;
}

/* Drops of the part at value, each drop's base pose (class), -1 if it did
 * not settle in one the base has. */
static pd_status drops_at(const design_ctx *ctx, const pd_static_result *bres,
                          const pd_static_options *opt, const double *value,
                          const int *class_of, const pd_scene *scene,
                          const pd_sim_options *sim, int *outcome, pd_diag *diag)
{
    pd_part *p;
    pd_static_result *r;
    pd_sim_result *s = NULL;
    int *map;
    pd_sim_options so = *sim;
    so.keep_trials = 1;
    pd_status st = changed_at(ctx, bres, opt, value, &p, &r, &map, diag);
    if (st != PD_OK)
        return st;
    st = pd_sim_run(p, r, scene, &so, &s, diag);
    if (st == PD_OK)
        for (long i = 0; i < sim->ndrops; i++) {
            int j = i < s->n ? s->trials[i].pose : -1;
            outcome[i] = j >= 0 && map[j] >= 0 ? class_index(class_of, map[j]) : -1;
        }
    pd_sim_result_free(s);
    free(map);
    pd_static_result_free(r);
    pd_part_free(p);
    return st;
}

pd_status pd_design_sensitivity(const pd_part *part, const pd_static_result *res,
                                const pd_static_options *options, const pd_change *changes,
                                int nchanges, const int *class_of, int nclasses,
                                const pd_scene *scene, const pd_sim_options *sim,
                                pd_design_sens **out, pd_diag *diag)
{
    pd_static_options opt;
    if (options)
        opt = *options;
    else
        pd_static_options_default(&opt);
    if (!part || !res || !out)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_sensitivity: NULL argument");
    if (opt.band == PD_PQS_BAND_EXACT && opt.epsilon > 0.0)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_sensitivity: the exact PQS band is a "
                       "quadrature and is not differentiated; use the rect band");
    int nc = class_of ? nclasses : res->nposes;
    if (res->nfacets != part->hull->nfacets || nc < 1 || nc > res->nposes)
        return pd_fail(diag, PD_ERR_USAGE, "pd_design_sensitivity: the static result or the "
                       "classes (%d) do not fit the part", nc);
    for (int i = 0; class_of && i < res->nposes; i++)
        if (class_of[i] < 0 || class_of[i] >= nc)
            return pd_fail(diag, PD_ERR_USAGE, "pd_design_sensitivity: pose %d's class %d is "
                           "out of 0..%d", i + 1, class_of[i], nc - 1);
    design_ctx ctx;
    pd_status st = design_ctx_init(&ctx, part, changes, nchanges, diag);
    if (st != PD_OK)
        return st;
    pd_scene sc;
    if (scene)
        sc = *scene;
    else
        pd_scene_default(&sc);
    long nd = sim ? sim->ndrops : 0;

    const pd_hull *h = part->hull;
    pd_design_sens *s = calloc(1, sizeof *s);
    pd_vec3 *dv = malloc(sizeof *dv * (size_t)h->nverts);
    double *dq = malloc(sizeof *dq * (size_t)(2 * h->nfacets + 4 * nc));
    int *oc = malloc(sizeof *oc * (size_t)(2 * (nd > 0 ? nd : 1)));
    if (!s || !dv || !dq || !oc || !(s->rows = calloc((size_t)(nc * nchanges), sizeof *s->rows))) {
        st = pd_fail(diag, PD_ERR_NOMEM, "pd_design_sensitivity: out of memory");
        goto done;
    }
    double *dp = dq + h->nfacets, *qp = dp + h->nfacets, *pp = qp + nc, *qm = pp + nc,
           *pm = qm + nc;
    s->nposes = nc;
    s->nchanges = nchanges;
    s->ndrops = nd;
    double value[PD_DESIGN_MAX_CHANGES];
    for (int k = 0; k < nchanges; k++)
        value[k] = design_identity(&changes[k]);
    for (int k = 0; k < nchanges && st == PD_OK; k++) {
        pd_vec3 dcom;
        design_motion(&ctx, part, k, dv, &dcom);
        st = pd_static_tangent(h, part->com, &opt, res, dv, dcom, NULL, dq, dp);
        if (st != PD_OK)
            break;
        for (int c = 0; c < nc; c++) {
            pd_design_sens_row *row = &s->rows[c * nchanges + k];
            row->pose = c;
            row->change = k;
        }
        for (int i = 0; i < res->nposes; i++) {
            pd_design_sens_row *row = &s->rows[class_index(class_of, i) * nchanges + k];
            row->d_qs += dq[res->poses[i].facet];
            row->d_pqs += dp[res->poses[i].facet];
        }
        /* A kink: the one-sided quotients disagree with the derivative. */
        double eps = changes[k].kind == PD_CHANGE_SCALE ? KINK_STEP_FACTOR
                                                         : KINK_STEP_FACTOR * part->size;
        double v0 = value[k];
        value[k] = v0 + eps;
        st = static_at(&ctx, res, &opt, value, class_of, nc, qp, pp, diag);
        value[k] = v0 - eps;
        if (st == PD_OK)
            st = static_at(&ctx, res, &opt, value, class_of, nc, qm, pm, diag);
        value[k] = v0;
        for (int c = 0; c < nc && st == PD_OK; c++) {
            pd_design_sens_row *row = &s->rows[c * nchanges + k];
            double fq = (qp[c] - qm[c]) / (2 * eps), fp = (pp[c] - pm[c]) / (2 * eps);
            row->qs_kink = fabs(fq - row->d_qs) > 0.1 * fmax(fabs(fq), fabs(row->d_qs)) + 1e-6;
            row->pqs_kink = fabs(fp - row->d_pqs) > 0.1 * fmax(fabs(fp), fabs(row->d_pqs)) + 1e-6;
        }
        if (st != PD_OK || nd <= 0)
            continue;
        double step = changes[k].kind == PD_CHANGE_SCALE ? STEP_FACTOR
                                                          : STEP_OFFSET_REL * part->size;
        s->step[k] = step;
        value[k] = v0 + step;
        st = drops_at(&ctx, res, &opt, value, class_of, &sc, sim, oc, diag);
        value[k] = v0 - step;
        if (st == PD_OK)
            st = drops_at(&ctx, res, &opt, value, class_of, &sc, sim, oc + nd, diag);
        value[k] = v0;
        for (int c = 0; c < nc && st == PD_OK; c++) {
            double sum = 0.0, sum2 = 0.0;
            for (long i = 0; i < nd; i++) {
                double d = (oc[i] == c) - (oc[nd + i] == c);
                sum += d;
                sum2 += d * d;
            }
            double mean = sum / (double)nd;
            double var = nd > 1 ? fmax(0.0, (sum2 - sum * mean) / (double)(nd - 1)) : 0.0;
            double half = 1.959963984540054 * sqrt(var / (double)nd) / (2 * step);
            pd_design_sens_row *row = &s->rows[c * nchanges + k];
            row->d_p = mean / (2 * step);
            row->lo = row->d_p - half;
            row->hi = row->d_p + half;
        }
    }
done:
    free(dv);
    free(dq);
    free(oc);
    if (st != PD_OK) {
        pd_design_sens_free(s);
        return st;
    }
    *out = s;
    return PD_OK;
}
