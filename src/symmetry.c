/* symmetry.c: the rotations of a part's hull about its centre of mass, and
 * the pose classes they induce.
 *
 * A rotation about the centre is fixed by where it sends two vertices a and b
 * that are not collinear with the centre. Any symmetry sends a to a vertex at
 * the same distance from the centre and b to one at b's distance from the
 * centre and from a's image, so those pairs are the only candidates; each is
 * kept if it sends every vertex onto a distinct vertex. Both frames are built
 * right-handed, so only proper rotations come out: a mirror image of the part
 * is a different part on the floor. */
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "diag.h"
#include "markov.h"
#include "posedrop/symmetry.h"
#include "posedrop/tolerances.h"
#include "stats.h"
#include "vec3.h"

/* --- vertex lookup ------------------------------------------------------------ *
 * A hash of grid cells of side 4 tol; a lookup visits the cells that meet the
 * cube of half-side tol around the point, 1.5 per axis on average (3.4 in
 * all, against 27 for a cell and all its neighbours). Coordinates are
 * relative to the centre and at most the size L, so cell indices stay below
 * L / (4 tol) = 2.5e4, well inside the 21 bits each gets in the key. */

enum { KEY_BITS = 21 };

typedef struct {
    double cell;
    int n;
    const pd_vec3 *w;
    uint64_t *key;     /* per vertex */
    int *sorted;       /* vertex indices by key */
    int *slot_first;   /* hash slot -> first position in sorted, -1 empty */
    size_t mask;
} vgrid;

static int64_t cell_of(double x, double cell)
{
    double c = floor(x / cell);
    const double lim = (double)((1 << (KEY_BITS - 1)) - 2);
    return (int64_t)(c < -lim ? -lim : c > lim ? lim : c);
}

static uint64_t pack(int64_t i, int64_t j, int64_t k)
{
    const int64_t off = 1 << (KEY_BITS - 1);
    return ((uint64_t)(i + off) << (2 * KEY_BITS)) | ((uint64_t)(j + off) << KEY_BITS) |
           (uint64_t)(k + off);
}

static size_t slot_of(uint64_t key, size_t mask)
{
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return (size_t)key & mask;
}

/* Sorted as (key, index) pairs: qsort takes no user pointer in C11, and a
 * file-scope one would make the library unsafe to call from two threads. */
typedef struct {
    uint64_t key;
    int idx;
} keyed;

static int by_key(const void *pa, const void *pb)
{
    const keyed *a = pa, *b = pb;
    return a->key < b->key ? -1 : a->key > b->key ? 1 : (a->idx > b->idx) - (a->idx < b->idx);
}

static void vgrid_free(vgrid *g)
{
    free(g->key);
    free(g->sorted);
    free(g->slot_first);
}

static int vgrid_build(vgrid *g, const pd_vec3 *w, int n, double tol)
{
    memset(g, 0, sizeof *g);
    g->cell = 4.0 * tol;
    g->n = n;
    g->w = w;
    size_t nslots = 16;
    while (nslots < 2 * (size_t)n)
        nslots *= 2;
    g->mask = nslots - 1;
    g->key = malloc(sizeof *g->key * (size_t)n);
    g->sorted = malloc(sizeof *g->sorted * (size_t)n);
    g->slot_first = malloc(sizeof *g->slot_first * nslots);
    keyed *tmp = malloc(sizeof *tmp * (size_t)n);
    if (!g->key || !g->sorted || !g->slot_first || !tmp) {
        free(tmp);
        vgrid_free(g);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        g->key[i] = pack(cell_of(w[i].x, g->cell), cell_of(w[i].y, g->cell),
                         cell_of(w[i].z, g->cell));
        tmp[i].key = g->key[i];
        tmp[i].idx = i;
    }
    qsort(tmp, (size_t)n, sizeof *tmp, by_key);
    for (int i = 0; i < n; i++)
        g->sorted[i] = tmp[i].idx;
    free(tmp);
    for (size_t s = 0; s < nslots; s++)
        g->slot_first[s] = -1;
    for (int p = 0; p < n; p++) {
        uint64_t k = g->key[g->sorted[p]];
        if (p > 0 && g->key[g->sorted[p - 1]] == k)
            continue;
        size_t s = slot_of(k, g->mask);
        while (g->slot_first[s] >= 0)
            s = (s + 1) & g->mask;
        g->slot_first[s] = p;
    }
    return 1;
}

/* The vertex nearest to x within tol, or -1. */
static int vgrid_nearest(const vgrid *g, pd_vec3 x, double tol)
{
    int64_t lo[3] = {cell_of(x.x - tol, g->cell), cell_of(x.y - tol, g->cell),
                     cell_of(x.z - tol, g->cell)};
    int64_t hi[3] = {cell_of(x.x + tol, g->cell), cell_of(x.y + tol, g->cell),
                     cell_of(x.z + tol, g->cell)};
    int best = -1;
    double best_d = tol;
    for (int64_t ci = lo[0]; ci <= hi[0]; ci++)
        for (int64_t cj = lo[1]; cj <= hi[1]; cj++)
            for (int64_t ck = lo[2]; ck <= hi[2]; ck++) {
                uint64_t k = pack(ci, cj, ck);
                size_t s = slot_of(k, g->mask);
                int p = -1;
                for (; g->slot_first[s] >= 0; s = (s + 1) & g->mask)
                    if (g->key[g->sorted[g->slot_first[s]]] == k) {
                        p = g->slot_first[s];
                        break;
                    }
                for (; p >= 0 && p < g->n && g->key[g->sorted[p]] == k; p++) {
                    int v = g->sorted[p];
                    double d = v3_dist(g->w[v], x);
                    if (d <= best_d) {
                        best_d = d;
                        best = v;
                    }
                }
            }
    return best;
}

/* --- the search --------------------------------------------------------------- */

/* Called once per rotation found, with perm[v] the image of hull vertex v.
 * Returns 0 to stop the search (out of memory). */
typedef int (*rotation_fn)(void *user, const double R[3][3], const int *perm);

typedef struct {
    double r;
    int idx;
} ranked;

static int by_radius(const void *pa, const void *pb)
{
    const ranked *a = pa, *b = pb;
    return a->r < b->r ? -1 : a->r > b->r ? 1 : (a->idx > b->idx) - (a->idx < b->idx);
}

/* Positions [lo, hi) in the radius order of vertices with |r - r0| <= tol. */
static void radius_window(const int *order, const double *r, int n, double r0, double tol,
                          int *lo, int *hi)
{
    int a = 0, b = n;
    while (a < b) {
        int m = a + (b - a) / 2;
        if (r[order[m]] < r0 - tol)
            a = m + 1;
        else
            b = m;
    }
    *lo = a;
    b = n;
    while (a < b) {
        int m = a + (b - a) / 2;
        if (r[order[m]] <= r0 + tol)
            a = m + 1;
        else
            b = m;
    }
    *hi = a;
}

/* The right-handed orthonormal frame (as columns) of u, then v's part
 * orthogonal to u. */
static void frame(pd_vec3 u, pd_vec3 v, double F[3][3])
{
    pd_vec3 e1 = v3_unit(u);
    pd_vec3 e2 = v3_unit(v3_sub(v, v3_scale(e1, v3_dot(v, e1))));
    pd_vec3 e3 = v3_cross(e1, e2);
    const pd_vec3 e[3] = {e1, e2, e3};
    for (int c = 0; c < 3; c++) {
        F[0][c] = e[c].x;
        F[1][c] = e[c].y;
        F[2][c] = e[c].z;
    }
}

static pd_vec3 rotate(const double R[3][3], pd_vec3 v)
{
    return v3(R[0][0] * v.x + R[0][1] * v.y + R[0][2] * v.z,
              R[1][0] * v.x + R[1][1] * v.y + R[1][2] * v.z,
              R[2][0] * v.x + R[2][1] * v.y + R[2][2] * v.z);
}

typedef struct {
    int n;
    pd_vec3 *w;        /* hull vertices minus the centre of mass */
    double *r;         /* their distances from it */
    int *order;        /* vertex indices by r */
    vgrid grid;
    int *perm, *used;  /* scratch of the check: used[v] == token marks a vertex
                          taken by the current candidate, so no clearing */
    int token;
    double tol;
} search_ctx;

static void ctx_free(search_ctx *c)
{
    free(c->w);
    free(c->r);
    free(c->order);
    free(c->perm);
    free(c->used);
    vgrid_free(&c->grid);
}

static int ctx_init(search_ctx *c, const pd_part *part)
{
    const pd_hull *h = part->hull;
    memset(c, 0, sizeof *c);
    c->n = h->nverts;
    c->tol = PD_TOL_SYMMETRY_REL * part->size;
    size_t n = (size_t)c->n;
    c->w = malloc(sizeof *c->w * n);
    c->r = malloc(sizeof *c->r * n);
    c->order = malloc(sizeof *c->order * n);
    c->perm = malloc(sizeof *c->perm * n);
    c->used = calloc(n ? n : 1, sizeof *c->used);
    ranked *tmp = malloc(sizeof *tmp * n);
    if (!c->w || !c->r || !c->order || !c->perm || !c->used || !tmp) {
        free(tmp);
        return 0;
    }
    for (int i = 0; i < c->n; i++) {
        c->w[i] = v3_sub(h->verts[i], part->com);
        c->r[i] = v3_norm(c->w[i]);
        tmp[i].r = c->r[i];
        tmp[i].idx = i;
    }
    qsort(tmp, n, sizeof *tmp, by_radius);
    for (int i = 0; i < c->n; i++)
        c->order[i] = tmp[i].idx;
    free(tmp);
    return vgrid_build(&c->grid, c->w, c->n, c->tol);
}

/* Does R send every vertex within tol of a distinct vertex? Fills c->perm. */
static int check_rotation(search_ctx *c, const double R[3][3])
{
    if (c->token == INT_MAX) {
        memset(c->used, 0, sizeof *c->used * (size_t)c->n);
        c->token = 0;
    }
    int token = ++c->token;
    for (int i = 0; i < c->n; i++) {
        int j = vgrid_nearest(&c->grid, rotate(R, c->w[i]), c->tol);
        if (j < 0 || c->used[j] == token)
            return 0;
        c->used[j] = token;
        c->perm[i] = j;
    }
    return 1;
}

/* Runs the search, calling found() for each rotation, the identity first.
 * *capped is set when the pair count is over PD_SYMMETRY_MAX_PAIRS (then only
 * the identity is reported). Returns 0 when found() asked to stop. */
static int search(search_ctx *c, rotation_fn found, void *user, int *capped, pd_diag *diag)
{
    const int n = c->n;
    const double tol = c->tol;
    static const double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    *capped = 0;
    for (int i = 0; i < n; i++)
        c->perm[i] = i;
    if (!found(user, identity, c->perm))
        return 0;

    /* Reference a: the vertex with the fewest others at its distance from the
     * centre, since every one of them is a candidate image; ties to the
     * farther vertex (a longer lever fixes the rotation better), then to the
     * lower index, so the search is the same on every run. */
    int a = -1, a_count = 0;
    for (int i = 0; i < n; i++) {
        int lo, hi;
        radius_window(c->order, c->r, n, c->r[i], tol, &lo, &hi);
        int cnt = hi - lo;
        if (a < 0 || cnt < a_count || (cnt == a_count && c->r[i] > c->r[a])) {
            a = i;
            a_count = cnt;
        }
    }
    /* Reference b: far enough off the line through the centre and a that the
     * frame is well conditioned (at least a quarter of the farthest vertex's
     * distance from that line), and among those again the one with the
     * fewest vertices at its distance from the centre. */
    pd_vec3 ua = v3_unit(c->w[a]);
    double dmax = 0.0;
    for (int i = 0; i < n; i++) {
        double d = v3_norm(v3_cross(ua, c->w[i]));
        if (d > dmax)
            dmax = d;
    }
    int b = -1, b_count = 0;
    double b_perp = 0.0;
    for (int i = 0; i < n; i++) {
        double d = v3_norm(v3_cross(ua, c->w[i]));
        if (d < 0.25 * dmax)
            continue;
        int lo, hi;
        radius_window(c->order, c->r, n, c->r[i], tol, &lo, &hi);
        int cnt = hi - lo;
        if (b < 0 || cnt < b_count || (cnt == b_count && d > b_perp)) {
            b = i;
            b_count = cnt;
            b_perp = d;
        }
    }
    if (b < 0 || (long long)a_count * b_count > PD_SYMMETRY_MAX_PAIRS) {
        *capped = 1;
        pd_warn(diag, "symmetry search skipped: %lld candidate images of the reference vertices "
                      "exceed the limit of %ld; poses are not grouped",
                (long long)a_count * b_count, (long)PD_SYMMETRY_MAX_PAIRS);
        return 1;
    }

    double F[3][3], G[3][3], R[3][3];
    frame(c->w[a], c->w[b], F);
    const double dab = v3_dist(c->w[a], c->w[b]);
    int alo, ahi, blo, bhi;
    radius_window(c->order, c->r, n, c->r[a], tol, &alo, &ahi);
    radius_window(c->order, c->r, n, c->r[b], tol, &blo, &bhi);
    for (int pa = alo; pa < ahi; pa++) {
        int a2 = c->order[pa];
        for (int pb = blo; pb < bhi; pb++) {
            int b2 = c->order[pb];
            if (a2 == b2 || fabs(v3_dist(c->w[a2], c->w[b2]) - dab) > tol)
                continue;
            if (a2 == a && b2 == b)
                continue; /* the identity, reported first */
            frame(c->w[a2], c->w[b2], G);
            /* R = G F^T sends a's frame onto the image frame. */
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    R[i][j] = G[i][0] * F[j][0] + G[i][1] * F[j][1] + G[i][2] * F[j][2];
            /* Each rotation is one (a2, b2) pair; requiring the check to send
             * a and b exactly there keeps a rotation from being counted twice
             * through a second vertex within tol of an image. */
            if (!check_rotation(c, (const double(*)[3])R) || c->perm[a] != a2 || c->perm[b] != b2)
                continue;
            if (!found(user, (const double(*)[3])R, c->perm))
                return 0;
        }
    }
    return 1;
}

/* --- public ------------------------------------------------------------------- */

typedef struct {
    int n, cap;
    double (*rot)[3][3];
} rot_list;

static int collect(void *user, const double R[3][3], const int *perm)
{
    (void)perm;
    rot_list *l = user;
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 64;
        void *p = realloc(l->rot, sizeof *l->rot * (size_t)cap);
        if (!p)
            return 0;
        l->rot = p;
        l->cap = cap;
    }
    memcpy(l->rot[l->n++], R, sizeof *l->rot);
    return 1;
}

pd_status pd_symmetry_find(const pd_part *part, pd_symmetry **symmetry, pd_diag *diag)
{
    *symmetry = NULL;
    search_ctx c;
    memset(&c, 0, sizeof c);
    rot_list l = {0, 0, NULL};
    int capped = 0;
    pd_symmetry *s = calloc(1, sizeof *s);
    if (!s || !ctx_init(&c, part) || !search(&c, collect, &l, &capped, diag)) {
        ctx_free(&c);
        free(l.rot);
        free(s);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory in the symmetry search");
    }
    ctx_free(&c);
    s->nrotations = l.n;
    s->rotation = l.rot;
    s->capped = capped;
    *symmetry = s;
    return PD_OK;
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
 * noise a symmetric hull's facets may have merged differently). */
static int image_facet(class_ctx *k, int f, const int *perm)
{
    const pd_hull *h = k->hull;
    int s = h->facet_start[f], e = h->facet_start[f + 1];
    if (k->token == INT_MAX) {
        memset(k->stamp, 0, sizeof *k->stamp * (size_t)h->nverts);
        k->token = 0;
    }
    int token = ++k->token;
    for (int i = s; i < e; i++)
        k->stamp[perm[h->facet_vert[i]]] = token;
    int v0 = perm[h->facet_vert[s]];
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

static int merge_poses(void *user, const double R[3][3], const int *perm)
{
    (void)R;
    class_ctx *k = user;
    for (int i = 0; i < k->res->nposes; i++) {
        int g = image_facet(k, k->res->poses[i].facet, perm);
        int j = g >= 0 ? k->pose_of[g] : -1;
        if (j < 0 || fabs(k->res->poses[i].height - k->res->poses[j].height) > k->tol)
            continue;
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

pd_status pd_pose_classes(const pd_part *part, const pd_static_result *res, int *class_of,
                          int *nclasses, pd_diag *diag)
{
    const pd_hull *h = part->hull;
    *nclasses = 0;
    for (int i = 0; i < res->nposes; i++)
        if (res->poses[i].facet < 0 || res->poses[i].facet >= h->nfacets)
            return pd_fail(diag, PD_ERR_USAGE, "pose %d rests on facet %d, not a facet of the "
                           "part's hull (%d facets)", i + 1, res->poses[i].facet, h->nfacets);
    if (res->nposes == 0)
        return PD_OK;

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
    search_ctx c;
    memset(&c, 0, sizeof c);
    int ok = k.parent && k.pose_of && k.vf_start && k.vf && k.stamp && ctx_init(&c, part);
    if (ok) {
        for (int i = 0; i < res->nposes; i++)
            k.parent[i] = i;
        for (size_t f = 0; f < nf; f++)
            k.pose_of[f] = -1;
        for (int i = 0; i < res->nposes; i++)
            k.pose_of[res->poses[i].facet] = i;
        for (size_t q = 0; q < ncorners; q++)
            k.vf_start[h->facet_vert[q] + 1]++;
        for (size_t v = 0; v < nv; v++)
            k.vf_start[v + 1] += k.vf_start[v];
        int *fill = c.perm; /* scratch until the search starts */
        memcpy(fill, k.vf_start, sizeof *fill * nv);
        for (int f = 0; f < h->nfacets; f++)
            for (int q = h->facet_start[f]; q < h->facet_start[f + 1]; q++)
                k.vf[fill[h->facet_vert[q]]++] = f;
        int capped;
        ok = search(&c, merge_poses, &k, &capped, diag);
    }
    if (ok) {
        /* Roots are each class's lowest pose, so numbering roots in pose order
         * numbers classes by first appearance. */
        int nc = 0;
        for (int i = 0; i < res->nposes; i++) {
            int r = root(k.parent, i);
            class_of[i] = r == i ? nc++ : class_of[r];
        }
        *nclasses = nc;
    }
    ctx_free(&c);
    free(k.parent);
    free(k.pose_of);
    free(k.vf_start);
    free(k.vf);
    free(k.stamp);
    return ok ? PD_OK : pd_fail(diag, PD_ERR_NOMEM, "out of memory grouping poses");
}

pd_status pd_sim_result_grouped(const pd_sim_result *sim, const int *class_of, int nclasses,
                                pd_sim_result **grouped, pd_diag *diag)
{
    *grouped = NULL;
    if (nclasses < 0 || (nclasses == 0 && sim->nposes > 0))
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_grouped: %d classes for %d poses",
                       nclasses, sim->nposes);
    for (int i = 0; i < sim->nposes; i++)
        if (class_of[i] < 0 || class_of[i] >= nclasses)
            return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_grouped: pose %d in class %d, "
                           "outside 0..%d", i + 1, class_of[i], nclasses - 1);
    pd_sim_result *g = malloc(sizeof *g);
    if (!g)
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    *g = *sim;
    g->nposes = nclasses;
    g->trials = NULL;
    g->first_count = NULL;
    g->transitions = NULL;
    size_t k = nclasses > 0 ? (size_t)nclasses : 1;
    g->count = calloc(k, sizeof *g->count);
    g->p = calloc(k, sizeof *g->p);
    g->ci_lo = calloc(k, sizeof *g->ci_lo);
    g->ci_hi = calloc(k, sizeof *g->ci_hi);
    if (sim->transitions) {
        g->first_count = calloc(k, sizeof *g->first_count);
        g->transitions = calloc(k * k, sizeof *g->transitions);
    }
    if (!g->count || !g->p || !g->ci_lo || !g->ci_hi ||
        (sim->transitions && (!g->first_count || !g->transitions))) {
        pd_sim_result_free(g);
        return pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    }
    size_t K = (size_t)sim->nposes;
    for (size_t i = 0; i < K; i++) {
        size_t ci = (size_t)class_of[i];
        g->count[ci] += sim->count[i];
        for (size_t j = 0; sim->transitions && j < K; j++)
            g->transitions[ci * k + (size_t)class_of[j]] += sim->transitions[i * K + j];
        if (sim->transitions)
            g->first_count[ci] += sim->first_count[i];
    }
    for (int c = 0; c < nclasses; c++) {
        g->p[c] = g->n ? (double)g->count[c] / (double)g->n : 0.0;
        pd_wilson(g->count[c], g->n, PD_Z95, &g->ci_lo[c], &g->ci_hi[c]);
    }
    if (sim->transitions && sim->closed_classes > 0) {
        /* pi of the pose chain, summed: the class chain of the summed
         * counts would be a different chain unless the part's symmetry
         * makes it lumpable. */
        pd_markov_counts mc = {sim->nposes, sim->first_count, sim->transitions};
        pd_markov_summary ms = {g->p, g->ci_lo, g->ci_hi, 0, 0.0};
        pd_status st = pd_markov_estimate(&mc, class_of, nclasses, sim->seed, &ms);
        if (st != PD_OK) {
            pd_sim_result_free(g);
            return pd_fail(diag, st, "grouping the long-run distribution: %s", pd_status_str(st));
        }
        g->stationary_shift = ms.shift;
    }
    *grouped = g;
    return PD_OK;
}
