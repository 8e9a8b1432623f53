/* symmetry.c: the rotations of a part's hull about its centre of mass (found
 * by symmetry_search.c), and the pose classes they induce. */
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "part/part_check.h"
#include "posedrop/symmetry.h"
#include "posedrop/tolerances.h"
#include "static/static_check.h"
#include "symmetry/symmetry_search.h"
#include "base/vec3.h"

/* --- public ------------------------------------------------------------------- */

typedef struct {
    int n, cap;
    double (*rot)[3][3];
    uint64_t *order;
} rot_list;

static int collect(void *user, const double R[3][3], const int *perm, uint64_t order)
{
    (void)perm;
    rot_list *l = user;
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 64;
        void *p = realloc(l->rot, sizeof *l->rot * (size_t)cap);
        if (p)
            l->rot = p;
        void *q = p ? realloc(l->order, sizeof *l->order * (size_t)cap) : NULL;
        if (!q)
            return 0;
        l->order = q;
        l->cap = cap;
    }
    memcpy(l->rot[l->n], R, sizeof *l->rot);
    l->order[l->n++] = order;
    return 1;
}

pd_status pd_symmetry_find_by(const pd_part *part, pd_symmetry_method method,
                              pd_symmetry **symmetry, pd_diag *diag)
{
    pd_status st = pd_part_check(part, "pd_symmetry_find", diag);
    if (st != PD_OK)
        return st;
    if (!symmetry)
        return pd_fail(diag, PD_ERR_USAGE, "pd_symmetry_find: NULL symmetry");
    rot_list l = {0, 0, NULL, NULL};
    int capped = 0;
    pd_symmetry *s = calloc(1, sizeof *s);
    st = s ? pd_symmetry_search(part, method, collect, &l, &capped, diag) : PD_ERR_NOMEM;
    if (st == PD_OK && !pd_symmetry_sort(l.rot, l.order, l.n))
        st = PD_ERR_NOMEM;
    free(l.order);
    if (st != PD_OK) {
        free(l.rot);
        free(s);
        return st == PD_ERR_NOMEM ? pd_fail(diag, st, "out of memory in the symmetry search") : st;
    }
    s->nrotations = l.n;
    s->rotation = l.rot;
    s->capped = capped;
    *symmetry = s;
    return PD_OK;
}

pd_status pd_symmetry_find(const pd_part *part, pd_symmetry **symmetry, pd_diag *diag)
{
    return pd_symmetry_find_by(part, PD_SYMMETRY_GENERATED, symmetry, diag);
}

void pd_symmetry_free(pd_symmetry *symmetry)
{
    if (!symmetry)
        return;
    free(symmetry->rotation);
    free(symmetry);
}

typedef struct {
    const pd_hull *hull;
    const pd_static_result *res;
    double tol;
    int *parent;       /* union-find over poses */
    int *pose_of;      /* facet -> pose, -1 if not stable */
    int *vf_start;     /* vertex -> incident facets (CSR) */
    int *vf;
    int *stamp;        /* per vertex, marks one mapped facet's corners */
    int token;
    int exact;         /* 1 while every rotation given with its perm has sent
                          every stable pose onto a stable pose of its height */
} class_ctx;

static int root(int *parent, int i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

/* The facet whose corners are exactly the images of facet f's, or -1 (under
 * noise a symmetric hull's facets may have merged differently). It is among
 * the facets at the image of any one corner: the corner with the fewest (a
 * cone's apex meets every side; its base's corners three facets each). */
static int image_facet(class_ctx *k, int f, const int *perm)
{
    const pd_hull *h = k->hull;
    int s = h->facet_start[f], e = h->facet_start[f + 1];
    if (k->token == INT_MAX) {
        memset(k->stamp, 0, sizeof *k->stamp * (size_t)h->nverts);
        k->token = 0;
    }
    int token = ++k->token;
    int v0 = perm[h->facet_vert[s]];
    for (int i = s; i < e; i++) {
        int v = perm[h->facet_vert[i]];
        k->stamp[v] = token;
        if (k->vf_start[v + 1] - k->vf_start[v] < k->vf_start[v0 + 1] - k->vf_start[v0])
            v0 = v;
    }
    for (int q = k->vf_start[v0]; q < k->vf_start[v0 + 1]; q++) {
        int g = k->vf[q];
        int gs = h->facet_start[g], ge = h->facet_start[g + 1];
        if (ge - gs != e - s)
            continue;
        int all = 1;
        for (int i = gs; i < ge && all; i++)
            all = k->stamp[h->facet_vert[i]] == token;
        if (all)
            return g;
    }
    return -1;
}

/* Joins each stable pose with its image. A rotation given without its perm
 * is a product of rotations given with theirs (symmetry_search.h), and so are
 * its pose images while those rotations each send every stable pose onto a
 * stable pose of its height (k->exact): products of them then join nothing
 * that they have not joined. */
static int merge_poses(void *user, const double R[3][3], const int *perm, uint64_t order)
{
    (void)R;
    (void)order;
    class_ctx *k = user;
    if (!perm)
        return 1;
    for (int i = 0; i < k->res->nposes; i++) {
        int g = image_facet(k, k->res->poses[i].facet, perm);
        int j = g >= 0 ? k->pose_of[g] : -1;
        if (j < 0 || fabs(k->res->poses[i].height - k->res->poses[j].height) > k->tol) {
            k->exact = 0;
            continue;
        }
        int ri = root(k->parent, i), rj = root(k->parent, j);
        /* The lower pose number becomes the root, so a class is named by its
         * first member. */
        if (ri < rj)
            k->parent[rj] = ri;
        else if (rj < ri)
            k->parent[ri] = rj;
    }
    return 1;
}

/* The union-find of the poses under the rotations, by method; with
 * PD_SYMMETRY_GENERATED, again exhaustively if a rotation did not map the
 * stable poses exactly onto each other (merge_poses). */
static pd_status join_poses(class_ctx *k, const pd_part *part, pd_symmetry_method method,
                            pd_diag *diag)
{
    for (int i = 0; i < k->res->nposes; i++)
        k->parent[i] = i;
    k->exact = 1;
    int capped;
    pd_status st = pd_symmetry_search(part, method, merge_poses, k, &capped, diag);
    if (st == PD_OK && !k->exact && method == PD_SYMMETRY_GENERATED)
        return join_poses(k, part, PD_SYMMETRY_EXHAUSTIVE, diag);
    return st;
}

/* Renumbers classes 0..nc-1 (numbered by first appearance) by decreasing
 * summed QS probability. The members of a class are symmetric, so the
 * sums order the classes as the paper's tables do; sums within
 * PD_TOL_PROB_TIE_REL of each other (round-off) keep the first-appearance
 * order, so the numbering does not hang on the last digits. */
static pd_status number_by_qs(const pd_static_result *res, int *class_of, int nc, pd_diag *diag)
{
    double *qs = calloc((size_t)nc, sizeof *qs);
    int *order = malloc(sizeof *order * (size_t)nc), *rank = malloc(sizeof *rank * (size_t)nc);
    pd_status st = qs && order && rank ? PD_OK
                                       : pd_fail(diag, PD_ERR_NOMEM, "out of memory grouping poses");
    if (st == PD_OK) {
        for (int i = 0; i < res->nposes; i++)
            qs[class_of[i]] += res->poses[i].p_qs;
        /* Insertion sort: stable, and classes are few. */
        for (int c = 0; c < nc; c++) {
            int j = c;
            while (j > 0 && qs[c] - qs[order[j - 1]] > PD_TOL_PROB_TIE_REL * qs[c]) {
                order[j] = order[j - 1];
                j--;
            }
            order[j] = c;
        }
        for (int j = 0; j < nc; j++)
            rank[order[j]] = j;
        for (int i = 0; i < res->nposes; i++)
            class_of[i] = rank[class_of[i]];
    }
    free(qs);
    free(order);
    free(rank);
    return st;
}

pd_status pd_pose_classes_by(const pd_part *part, const pd_static_result *res,
                             pd_symmetry_method method, int *class_of, int *nclasses,
                             pd_diag *diag)
{
    pd_status st = pd_static_result_check(part, res, "pd_pose_classes", diag);
    if (st != PD_OK)
        return st;
    if (!class_of || !nclasses)
        return pd_fail(diag, PD_ERR_USAGE, "pd_pose_classes: NULL %s",
                       class_of ? "nclasses" : "class_of");
    const pd_hull *h = part->hull;
    if (res->nposes == 0) {
        *nclasses = 0;
        return PD_OK;
    }

    class_ctx k;
    memset(&k, 0, sizeof k);
    k.hull = h;
    k.res = res;
    k.tol = PD_TOL_SYMMETRY_REL * part->size;
    size_t nv = (size_t)h->nverts, nf = (size_t)h->nfacets;
    size_t ncorners = (size_t)h->facet_start[h->nfacets];
    k.parent = malloc(sizeof *k.parent * (size_t)res->nposes);
    k.pose_of = malloc(sizeof *k.pose_of * nf);
    k.vf_start = calloc(nv + 1, sizeof *k.vf_start);
    k.vf = malloc(sizeof *k.vf * ncorners);
    k.stamp = calloc(nv, sizeof *k.stamp);
    int *fill = malloc(sizeof *fill * (nv ? nv : 1));
    st = k.parent && k.pose_of && k.vf_start && k.vf && k.stamp && fill
                       ? PD_OK
                       : pd_fail(diag, PD_ERR_NOMEM, "out of memory grouping poses");
    if (st == PD_OK) {
        for (size_t f = 0; f < nf; f++)
            k.pose_of[f] = -1;
        for (int i = 0; i < res->nposes; i++)
            k.pose_of[res->poses[i].facet] = i;
        for (size_t q = 0; q < ncorners; q++)
            k.vf_start[h->facet_vert[q] + 1]++;
        for (size_t v = 0; v < nv; v++)
            k.vf_start[v + 1] += k.vf_start[v];
        memcpy(fill, k.vf_start, sizeof *fill * nv);
        for (int f = 0; f < h->nfacets; f++)
            for (int q = h->facet_start[f]; q < h->facet_start[f + 1]; q++)
                k.vf[fill[h->facet_vert[q]]++] = f;
        st = join_poses(&k, part, method, diag);
    }
    if (st == PD_OK) {
        /* Roots are each class's lowest pose, so numbering roots in pose order
         * numbers classes by first appearance; then by QS, most probable
         * first, as the poses are. */
        int nc = 0;
        for (int i = 0; i < res->nposes; i++) {
            int r = root(k.parent, i);
            class_of[i] = r == i ? nc++ : class_of[r];
        }
        st = number_by_qs(res, class_of, nc, diag);
        *nclasses = nc;
    }
    free(fill);
    free(k.parent);
    free(k.pose_of);
    free(k.vf_start);
    free(k.vf);
    free(k.stamp);
    return st;
}

pd_status pd_pose_classes(const pd_part *part, const pd_static_result *res, int *class_of,
                          int *nclasses, pd_diag *diag)
{
    return pd_pose_classes_by(part, res, PD_SYMMETRY_GENERATED, class_of, nclasses, diag);
}
