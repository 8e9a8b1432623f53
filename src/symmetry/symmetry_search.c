/* symmetry_search.c: the rotations of a part's hull about its centre of mass.
 *
 * A rotation about the centre is fixed by where it sends two vertices a and b
 * that are not collinear with the centre. Any symmetry sends a to a vertex at
 * the same distance from the centre and b to one at b's distance from the
 * centre and from a's image, so those pairs are the only candidates; a
 * candidate is a symmetry if it sends every vertex onto a distinct vertex.
 * Both frames are built right-handed, so only proper rotations come out: a
 * mirror image of the part is a different part on the floor.
 *
 * Checking every candidate vertex by vertex (PD_SYMMETRY_EXHAUSTIVE) costs n
 * lookups per rotation, and a body of revolution of n vertices has O(n)
 * rotations: O(n^2), 6.5 s for a 4000-gon prism. PD_SYMMETRY_GENERATED uses
 * that the rotations form a group. A rotation is named by its pair (x, y),
 * the images of a and b, and each one found vertex by vertex (a generator)
 * comes with its vertex permutation, so the pairs of every product of
 * generators follow by permuting indices: the orbit of (a, b) under the
 * generators. A candidate pair already in that orbit is not checked; one
 * outside it is, and if it is a symmetry it is a new generator, which at
 * least doubles the orbit (Lagrange), so there are at most log2 of the
 * group's order of them. The candidates that are not symmetries are checked
 * as before and fail at their first vertices.
 *
 * What comes out is exactly what the exhaustive search gives. An orbit pair
 * is reported only if the exhaustive loop would meet it (the same window and
 * distance tests on the same numbers), with the matrix built from its frame
 * as there, and only if that matrix passes the exhaustive check, which is
 * either run (see below) or certified: each generator's check measured how
 * far its images fall from their vertices (e_g), so a product of generators
 * M sends every vertex v within E = sum of the e_g (plus round-off) of its
 * permuted vertex p(v). The frame matrix of the same pair differs from M by a
 * rotation that the bound on a's and b's images limits (frame_bound), so it
 * too sends every vertex near p(v). If that is within the tolerance and half
 * the closest two vertices' distance, the exhaustive check finds p(v) as
 * the nearest vertex within the tolerance for every v: it passes, with
 * perm = p. Where the bound is too loose (a noisy hull, long products) the
 * same is shown by measuring each vertex's distance from p(v) (no lookup),
 * and the bound restarts from that; a pair that fails that too is checked
 * by lookups as in the exhaustive search. Candidates the exhaustive loop
 * would check are thus either in the orbit, and decided as it decides them,
 * or checked by it; no pair outside the loop's candidates is reported.
 * What stays O(n^2) is the scan of the candidate pairs, a few ns each. */
#include <float.h>
#include <limits.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/mat3.h"
#include "posedrop/tolerances.h"
#include "symmetry/symmetry_orbit.h"
#include "symmetry/symmetry_search.h"
#include "base/vec3.h"
#include "symmetry/vertex_grid.h"

/* Round-off allowances of the certificate, in units of the largest vertex
 * distance from the centre. They are not tolerances: a larger value only
 * sends more pairs to the vertex-by-vertex check; they must not be smaller
 * than the round-off they cover. Per product with a generator: the
 * generator's error as measured (a rotated vector and a distance, a few
 * epsilon) and the product's drift from orthogonality (a few epsilon per
 * factor); at the end: the frame matrix's own construction, the check's
 * arithmetic and the measured separation of the vertices (a few epsilon
 * each). 16 epsilon covers each with room. */
#define ROUNDOFF_PER_PRODUCT (16.0 * DBL_EPSILON)
#define ROUNDOFF_FINAL (16.0 * DBL_EPSILON)

/* --- the candidates ------------------------------------------------------------ */

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

typedef struct {
    int n;
    pd_vec3 *w;        /* hull vertices minus the centre of mass */
    double *r;         /* their distances from it */
    int *order;        /* vertex indices by r */
    int *rank;         /* position of each vertex in order */
    pd_vgrid grid;
    int *perm, *used;  /* scratch of the check: used[v] == token marks a vertex
                          taken by the current candidate, so no clearing */
    int token;
    double err;        /* the last passed check's largest image-to-vertex distance */
    double tol;
    /* The reference vertices and their candidates' windows (positions in
     * order), a's and b's distance and b's distance from the line through
     * the centre and a, and their frame. */
    int a, b, alo, ahi, blo, bhi;
    double dab, b_perp;
    double F[3][3];
} search_ctx;

static void ctx_free(search_ctx *c)
{
    free(c->w);
    free(c->r);
    free(c->order);
    free(c->rank);
    free(c->perm);
    free(c->used);
    pd_vgrid_free(&c->grid);
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
    c->rank = malloc(sizeof *c->rank * n);
    c->perm = malloc(sizeof *c->perm * n);
    c->used = calloc(n ? n : 1, sizeof *c->used);
    ranked *tmp = malloc(sizeof *tmp * n);
    if (!c->w || !c->r || !c->order || !c->rank || !c->perm || !c->used || !tmp) {
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
    for (int i = 0; i < c->n; i++) {
        c->order[i] = tmp[i].idx;
        c->rank[tmp[i].idx] = i;
    }
    free(tmp);
    return pd_vgrid_build(&c->grid, c->w, c->n, c->tol);
}

/* Does R send every vertex within tol of a distinct vertex? Fills c->perm
 * and, when it does, c->err. */
static int check_rotation(search_ctx *c, const double R[3][3])
{
    if (c->token == INT_MAX) {
        memset(c->used, 0, sizeof *c->used * (size_t)c->n);
        c->token = 0;
    }
    int token = ++c->token;
    double err = 0.0;
    for (int i = 0; i < c->n; i++) {
        double d;
        int j = pd_vgrid_nearest(&c->grid, m3_vec(R, c->w[i]), c->tol, -1, &d);
        if (j < 0 || c->used[j] == token)
            return 0;
        c->used[j] = token;
        c->perm[i] = j;
        err = d > err ? d : err;
    }
    c->err = err;
    return 1;
}

/* Picks the reference vertices a and b and their candidate windows. Returns
 * 0 if there is no usable b. */
static int choose_references(search_ctx *c)
{
    const int n = c->n;
    const double tol = c->tol;
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
    c->a = a;
    c->b = b;
    c->b_perp = b_perp;
    if (b < 0)
        return 0;
    frame(c->w[a], c->w[b], c->F);
    c->dab = v3_dist(c->w[a], c->w[b]);
    radius_window(c->order, c->r, n, c->r[a], tol, &c->alo, &c->ahi);
    radius_window(c->order, c->r, n, c->r[b], tol, &c->blo, &c->bhi);
    return 1;
}

/* The candidate loop's test of a pair from the windows: two vertices as far
 * apart as a and b. */
static int is_near_pair(const search_ctx *c, int a2, int b2)
{
    return !(a2 == b2 || fabs(v3_dist(c->w[a2], c->w[b2]) - c->dab) > c->tol);
}

/* Is (a2, b2) a pair the candidate loop checks? Windows by position, then
 * the loop's test, on the same numbers. */
static int is_candidate(const search_ctx *c, int a2, int b2)
{
    return c->rank[a2] >= c->alo && c->rank[a2] < c->ahi && c->rank[b2] >= c->blo &&
           c->rank[b2] < c->bhi && is_near_pair(c, a2, b2);
}

/* The rotation sending a's frame onto the frame of (a2, b2): R = G F^T. */
static void candidate_rotation(const search_ctx *c, int a2, int b2, double R[3][3])
{
    double G[3][3];
    frame(c->w[a2], c->w[b2], G);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            R[i][j] = G[i][0] * c->F[j][0] + G[i][1] * c->F[j][1] + G[i][2] * c->F[j][2];
}

/* Where the exhaustive loop meets the pair (a2, b2): after the identity (0),
 * by a2's position in the radius order, then b2's. */
static uint64_t pair_order(const search_ctx *c, int a2, int b2)
{
    return 1 + (uint64_t)c->rank[a2] * (uint64_t)c->n + (uint64_t)c->rank[b2];
}

/* The check of the candidate (a2, b2), which must also send a and b exactly
 * there: a rotation is then one pair, never counted twice through a second
 * vertex within tol of an image. */
static int check_candidate(search_ctx *c, int a2, int b2, double R[3][3])
{
    candidate_rotation(c, a2, b2, R);
    return check_rotation(c, CONST_M3(R)) && c->perm[c->a] == a2 && c->perm[c->b] == b2;
}

/* --- the search ------------------------------------------------------------------ */

/* The exhaustive loop, or (generated) the same loop finding generators.
 * Returns 1, 0 (found() stopped it, or out of memory) or PD_ORBIT_TOO_LARGE. */
static int candidate_loop(search_ctx *c, pd_symmetry_method method, pd_orbit *g,
                          pd_rotation_fn found, void *user)
{
    double R[3][3];
    /* A square distance outside [(dab - 2 tol)^2, (dab + 2 tol)^2] fails the
     * loop's test by a margin no round-off closes: skipped without its
     * square root (the loop runs up to PD_SYMMETRY_MAX_PAIRS times), by one
     * comparison with the interval's middle. One branch, nearly always
     * taken; two (above hi, below lo) would each be as unpredictable as the
     * order of b's window around the part is (noisy radii), and mispredicted
     * half the time: 3.5 times slower on a float STL cylinder. */
    const double hi2 = (c->dab + 2.0 * c->tol) * (c->dab + 2.0 * c->tol);
    const double lo = c->dab - 2.0 * c->tol, lo2 = lo > 0.0 ? lo * lo : 0.0;
    const double mid2 = 0.5 * (hi2 + lo2), half2 = 0.5 * (hi2 - lo2);
    /* b's window in order, contiguous: the inner loop reads it a_count times. */
    pd_vec3 *wb = malloc(sizeof *wb * (size_t)(c->bhi - c->blo + 1));
    if (!wb)
        return 0;
    for (int pb = c->blo; pb < c->bhi; pb++)
        wb[pb - c->blo] = c->w[c->order[pb]];
    int ok = 1;
    for (int pa = c->alo; ok == 1 && pa < c->ahi; pa++) {
        int a2 = c->order[pa];
        const pd_vec3 wa2 = c->w[a2];
        for (int pb = c->blo; ok == 1 && pb < c->bhi; pb++) {
            pd_vec3 d = v3_sub(wb[pb - c->blo], wa2);
            double d2 = v3_dot(d, d);
            int b2 = c->order[pb];
            if (fabs(d2 - mid2) > half2 || !is_near_pair(c, a2, b2))
                continue;
            if (method == PD_SYMMETRY_EXHAUSTIVE) {
                if (a2 == c->a && b2 == c->b)
                    continue; /* the identity, reported first */
                if (check_candidate(c, a2, b2, R))
                    ok = found(user, CONST_M3(R), c->perm, pair_order(c, a2, b2));
            } else if (pd_orbit_find(g, a2, b2) < 0 && check_candidate(c, a2, b2, R)) {
                ok = pd_orbit_add_generator(g, c->perm, c->err);
            }
        }
    }
    free(wb);
    return ok;
}

/* The closest two vertices' distance, or radius if none are closer. */
static double min_separation(const search_ctx *c, double radius)
{
    double sep = radius;
    for (int v = 0; v < c->n; v++) {
        double d;
        pd_vgrid_nearest(&c->grid, c->w[v], radius, v, &d);
        sep = d < sep ? d : sep;
    }
    return sep;
}

/* --- deciding the generated rotations ------------------------------------------- *
 * Every element of the orbit but the identity is decided as the exhaustive
 * loop would decide its pair: a rotation R that sends every vertex v within
 * limit = min(tol, sep / 2) (less round-off) of its permuted vertex p(v),
 * sep the closest two vertices' distance, passes the exhaustive check with
 * perm = p: p(v) is within tol, any other vertex is farther than sep / 2.
 * That is shown by the bound on the element's product matrix (frame_bound)
 * where it is tight enough, else by measuring each vertex's distance to its
 * permuted vertex: a product and a distance per vertex, not a lookup. Only
 * a pair that fails both is checked by lookups. The permutation of an
 * element is its generator's times its parent's, so the elements are
 * visited depth first over the tree of parents, carrying permutations: each
 * node's largest subtree inherits its buffer, the others get copies, so at
 * most (generators) x log2(elements) buffers live at once. */

enum { ELT_OUT, ELT_CERTIFIED, ELT_CHECKED };
enum { DECIDED = 1, NEED_PERMS = 2 };

typedef struct {
    search_ctx *c;
    pd_orbit *g;
    double ra, rb, b_perp, rmax; /* the references' distances, the largest */
    double limit;
    double *bound;        /* per element: its product matrix's largest error */
    unsigned char *how;
    int *kid_start, *kids; /* children of each element, smallest subtree first */
    int **pool;            /* free permutation buffers */
    int npool;
    pd_rotation_fn found;  /* called as each element is decided, if not NULL */
    void *user;
} decider;

/* How far the frame matrix of an element can send a vertex from its permuted
 * vertex, given a product matrix M that sends every vertex within E of it.
 * The element's frame (of x, y) and M's (of M a, M b) differ by a rotation:
 * their first axes by t1 <= asin(E / ra) (a's image moved by E, seen from
 * the centre at ra); their second by t2 <= asin((E + rb sin t1) / b_perp)
 * (b's part off the first axis moves by E, and by rb sin t1 as that axis
 * turns, at b_perp from it); so the frame turns by at most t1 (the first
 * axis) and then 2 asin((t1 + t2) / 2) about it, which moves a vertex at
 * rmax by at most that angle times rmax, on top of M's own E. */
static double frame_bound(const decider *d, double e)
{
    double t1 = asin(fmin(1.0, e / d->ra));
    double t2 = asin(fmin(1.0, (e + d->rb * sin(t1)) / d->b_perp));
    return e + (t1 + 2.0 * asin(fmin(1.0, 0.5 * (t1 + t2)))) * d->rmax;
}

/* Does the rotation of el send every vertex within limit of its image
 * under perm? *maxd receives the largest distance. */
static int near_permuted(const search_ctx *c, pd_orbit_elt el, const int *perm, double limit,
                         double *maxd)
{
    double R[3][3], m = 0.0;
    candidate_rotation(c, el.x, el.y, R);
    for (int v = 0; v < c->n; v++) {
        double d = v3_dist(c->w[perm[v]], m3_vec(CONST_M3(R), c->w[v]));
        if (!(d <= limit))
            return 0;
        m = d > m ? d : m;
    }
    *maxd = m;
    return 1;
}

/* Reports element i unless it is out, with its permutation if it was
 * checked. Returns found()'s verdict. */
static int report(decider *d, int i, const int *rho)
{
    pd_orbit_elt el = d->g->e[i];
    double R[3][3];
    if (d->how[i] == ELT_OUT)
        return 1;
    candidate_rotation(d->c, el.x, el.y, R);
    return d->found(d->user, CONST_M3(R), d->how[i] == ELT_CHECKED ? rho : NULL,
                    pair_order(d->c, el.x, el.y));
}

/* Decides element i, whose permutation rho (NULL when not carried) and
 * bound[i] are its parent's times its generator, and reports it if d->found
 * is set. Returns DECIDED, NEED_PERMS when rho is needed and absent, or 0
 * when found() stopped the search; may replace rho's contents by the
 * checked permutation. */
static int decide(decider *d, int i, int *rho)
{
    search_ctx *c = d->c;
    pd_orbit_elt el = d->g->e[i];
    double R[3][3], maxd;
    if (el.parent == 0) {
        /* Parent 0 marks the generators: a generator's closure applies it to
         * the identity first, and its pair was not in the orbit (else it
         * would not have been checked), so that is where its element comes
         * from; the identity gets no other generator applied later. */
        d->how[i] = ELT_CHECKED;
    } else if (!is_candidate(c, el.x, el.y)) {
        d->how[i] = ELT_OUT;
    } else if (frame_bound(d, d->bound[i]) <= d->limit) {
        d->how[i] = ELT_CERTIFIED;
    } else if (!rho) {
        return NEED_PERMS;
    } else if (near_permuted(c, el, rho, d->limit, &maxd)) {
        d->how[i] = ELT_CERTIFIED;
        d->bound[i] = maxd; /* its own matrix, measured */
    } else if (check_candidate(c, el.x, el.y, R)) {
        d->how[i] = ELT_CHECKED;
        d->bound[i] = c->err;
        memcpy(rho, c->perm, sizeof *rho * (size_t)c->n);
    } else {
        d->how[i] = ELT_OUT;
    }
    return d->found && !report(d, i, rho) ? 0 : DECIDED;
}

static int *buffer_get(decider *d)
{
    return d->npool ? d->pool[--d->npool] : malloc(sizeof(int) * (size_t)d->c->n);
}

/* The pool has room for every buffer ever allocated (see decide_all). */
static void buffer_put(decider *d, int *buf)
{
    if (buf)
        d->pool[d->npool++] = buf;
}

/* Children lists, each by subtree size, smallest first (parents precede
 * children in the element array, so sizes accumulate backwards). */
static int build_tree(decider *d)
{
    const pd_orbit *g = d->g;
    size_t ne = (size_t)g->n;
    uint64_t *size = malloc(sizeof *size * ne);
    int *fill = malloc(sizeof *fill * (ne + 1));
    pd_keyed *list = malloc(sizeof *list * ne);
    d->kid_start = calloc(ne + 1, sizeof *d->kid_start);
    d->kids = malloc(sizeof *d->kids * ne);
    int ok = size && fill && list && d->kid_start && d->kids;
    if (ok) {
        for (int i = 0; i < g->n; i++)
            size[i] = 1;
        for (int i = g->n - 1; i > 0; i--) {
            size[g->e[i].parent] += size[i];
            d->kid_start[g->e[i].parent + 1]++;
        }
        for (int i = 0; i < g->n; i++)
            d->kid_start[i + 1] += d->kid_start[i];
        memcpy(fill, d->kid_start, sizeof *fill * (ne + 1));
        for (int i = 1; i < g->n; i++) {
            int q = fill[g->e[i].parent]++;
            list[q].key = size[i];
            list[q].idx = i;
        }
        for (int u = 0; u < g->n; u++) {
            int s = d->kid_start[u], e = d->kid_start[u + 1];
            qsort(list + s, (size_t)(e - s), sizeof *list, pd_keyed_cmp);
            for (int q = s; q < e; q++)
                d->kids[q] = list[q].idx;
        }
    }
    free(size);
    free(fill);
    free(list);
    return ok;
}

typedef struct {
    int node;
    int *rho;  /* its permutation, NULL when not carried */
} visit;

/* rho = perm o rho, or a copy of that into a new buffer. */
static int *compose(decider *d, const int *perm, int *rho, int copy)
{
    int *out = copy ? buffer_get(d) : rho;
    if (out)
        for (int v = 0; v < d->c->n; v++)
            out[v] = perm[rho[v]];
    return out;
}

/* Decides every element, depth first from the identity, carrying
 * permutations or not; without them it stops with NEED_PERMS at the first
 * element the bound does not decide. Returns DECIDED, NEED_PERMS or 0 (out
 * of memory). */
static int decide_all(decider *d, int carry)
{
    const pd_orbit *g = d->g;
    visit *stack = malloc(sizeof *stack * (size_t)g->n);
    d->pool = malloc(sizeof *d->pool * (size_t)g->n);
    d->npool = 0;
    int status = stack && d->pool ? DECIDED : 0, sp = 0;
    int *rho0 = status && carry ? buffer_get(d) : NULL;
    if (carry && !rho0)
        status = 0;
    for (int v = 0; rho0 && v < d->c->n; v++)
        rho0[v] = v;
    if (status) {
        d->bound[0] = 0.0;
        stack[sp++] = (visit){0, rho0};
    }
    while (status == DECIDED && sp > 0) {
        visit it = stack[--sp];
        int u = it.node;
        if (u != 0 && (status = decide(d, u, it.rho)) != DECIDED) {
            buffer_put(d, it.rho);
            break;
        }
        int s = d->kid_start[u], e = d->kid_start[u + 1];
        for (int q = s; q < e; q++) {
            int kid = d->kids[q];
            d->bound[kid] = d->bound[u] + g->err[g->e[kid].gen] + ROUNDOFF_PER_PRODUCT * d->rmax;
        }
        if (s == e) {
            buffer_put(d, it.rho);
            continue;
        }
        /* The largest subtree goes below the others on the stack, so it is
         * visited last, and takes over this buffer once the others have
         * copied it. */
        int big = sp++;
        for (int q = s; q < e - 1; q++) {
            int kid = d->kids[q];
            int *rho = carry ? compose(d, g->perm[g->e[kid].gen], it.rho, 1) : NULL;
            if (carry && !rho)
                status = 0;
            stack[sp++] = (visit){kid, rho};
        }
        int kid = d->kids[e - 1];
        stack[big] = (visit){kid, carry ? compose(d, g->perm[g->e[kid].gen], it.rho, 0) : NULL};
    }
    while (sp > 0)
        buffer_put(d, stack[--sp].rho);
    for (int i = 0; i < d->npool; i++)
        free(d->pool[i]);
    free(d->pool);
    d->pool = NULL;
    free(stack);
    return status;
}

/* Decides every element of the orbit (the identity aside) as the exhaustive
 * loop would, and reports those that are rotations. First without
 * permutations, reporting afterwards (only the generators are checked then,
 * and checked again for their permutations); if the bound does not decide
 * them all, again with permutations, reporting each as it is decided. */
static int report_generated(search_ctx *c, pd_orbit *g, pd_rotation_fn found, void *user)
{
    size_t ne = (size_t)g->n;
    decider d;
    memset(&d, 0, sizeof d);
    d.c = c;
    d.g = g;
    d.user = user;
    d.bound = malloc(sizeof *d.bound * ne);
    d.how = malloc(ne);
    d.rmax = c->r[c->order[c->n - 1]];
    d.ra = c->r[c->a];
    d.rb = c->r[c->b];
    d.b_perp = c->b_perp;
    d.limit = fmin(c->tol, 0.5 * min_separation(c, 2.0 * c->tol)) - ROUNDOFF_FINAL * d.rmax;
    int st = d.bound && d.how && build_tree(&d) ? decide_all(&d, 0) : 0;
    d.found = found;
    if (st == NEED_PERMS) {
        st = decide_all(&d, 1);
    } else {
        double R[3][3];
        for (int i = 1; st == DECIDED && i < g->n; i++) {
            pd_orbit_elt el = g->e[i];
            if (d.how[i] == ELT_CHECKED) /* a generator */
                check_candidate(c, el.x, el.y, R);
            st = report(&d, i, c->perm) ? DECIDED : 0;
        }
    }
    free(d.bound);
    free(d.how);
    free(d.kid_start);
    free(d.kids);
    return st == DECIDED;
}

int pd_symmetry_sort(double (*rot)[3][3], const uint64_t *order, int n)
{
    size_t m = n > 0 ? (size_t)n : 1;
    pd_keyed *k = malloc(sizeof *k * m);
    double(*out)[3][3] = malloc(sizeof *out * m);
    if (k && out) {
        for (int i = 0; i < n; i++)
            k[i] = (pd_keyed){order[i], i};
        qsort(k, (size_t)n, sizeof *k, pd_keyed_cmp);
        for (int i = 0; i < n; i++)
            memcpy(out[i], rot[k[i].idx], sizeof *out);
        memcpy(rot, out, sizeof *out * (size_t)n);
    }
    int ok = k && out;
    free(k);
    free(out);
    return ok;
}

pd_status pd_symmetry_search(const pd_part *part, pd_symmetry_method method, pd_rotation_fn found,
                             void *user, int *capped, pd_diag *diag)
{
    static const double identity[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    search_ctx c;
    pd_orbit g;
    memset(&g, 0, sizeof g);
    *capped = 0;
    int ok = ctx_init(&c, part);
    if (ok) {
        for (int i = 0; i < c.n; i++)
            c.perm[i] = i;
        ok = found(user, identity, c.perm, 0);
    }
    if (ok && c.n > 0) {
        int have_b = choose_references(&c);
        long long pairs = (long long)(c.ahi - c.alo) * (c.bhi - c.blo);
        if (!have_b || pairs > PD_SYMMETRY_MAX_PAIRS) {
            *capped = 1;
            pd_warn(diag, "symmetry search skipped: %lld candidate images of the reference "
                          "vertices exceed the limit of %ld; poses are not grouped",
                    have_b ? pairs : 0LL, (long)PD_SYMMETRY_MAX_PAIRS);
        } else {
            ok = method == PD_SYMMETRY_EXHAUSTIVE || pd_orbit_init(&g, c.n, c.a, c.b);
            if (ok)
                ok = candidate_loop(&c, method, &g, found, user);
            if (ok == PD_ORBIT_TOO_LARGE)
                ok = candidate_loop(&c, PD_SYMMETRY_EXHAUSTIVE, &g, found, user);
            else if (ok && method == PD_SYMMETRY_GENERATED)
                ok = report_generated(&c, &g, found, user);
        }
    }
    pd_orbit_free(&g);
    ctx_free(&c);
    return ok ? PD_OK : pd_fail(diag, PD_ERR_NOMEM, "out of memory in the symmetry search");
}
