/* mesh_weld.c: merging vertices closer than a tolerance.
 *
 * Vertices are visited in input order; each maps onto the earliest surviving
 * representative within tol, or becomes a representative itself. Only
 * representatives are searched, so the result does not depend on hash order
 * and a chain of vertices each within tol of the next does not collapse into
 * one point much wider than tol. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include "mesh/mesh_internal.h"
#include "mesh/mesh_reader.h"
#include "base/vec3.h"

/* Coordinates in cell units are kept below this, so a quotient v / w is
 * rounded by at most half an ulp of 2^44, 2^-9, and cell indices and their
 * neighbours cannot overflow an int64_t. Above it the grid is not used. */
#define CELL_LIMIT 0x1p44
/* Bound on how much two computed quotients can differ beyond the true
 * difference: two roundings of 2^-9 each, plus the relative round-off of the
 * distance test, far smaller. */
#define CELL_SLACK 0x1p-8

/* A slot of the hash table of cells: the latest representative in the
 * cell (-1 for an empty slot) and 32 bits of the cell's hash. The cell
 * itself is not stored: it is that of its representative, recomputed when
 * the bits match. 8 bytes, where the cell's three 64-bit indices made 32:
 * a quarter of the table's cache misses and page faults. */
typedef struct cell {
    uint32_t tag;
    int head;
} cell;

typedef struct grid {
    cell *slot;
    size_t mask;
    int *next; /* next representative in the same cell */
    const pd_vec3 *verts;
    double w;  /* the cells' width */
} grid;

static uint64_t cell_hash(const int64_t c[3])
{
    uint64_t h = 0x9e3779b97f4a7c15ULL;
    for (int i = 0; i < 3; i++) {
        h ^= (uint64_t)c[i];
        h *= 0xbf58476d1ce4e5b9ULL;
        h ^= h >> 31;
    }
    return h;
}

/* The cell of point v and where v lies in it, in cell units. */
static void cell_of(pd_vec3 v, double w, int64_t c[3], double frac[3])
{
    double u[3] = {v.x / w, v.y / w, v.z / w};
    for (int k = 0; k < 3; k++) {
        double f = floor(u[k]);
        c[k] = (int64_t)f;
        frac[k] = u[k] - f;
    }
}

/* The slot of cell c: the cell itself, or the empty slot where it would go. */
static cell *find_cell(const grid *g, const int64_t c[3])
{
    uint64_t h = cell_hash(c);
    uint32_t tag = (uint32_t)(h >> 32);
    size_t i = (size_t)h & g->mask;
    for (;; i = (i + 1) & g->mask) {
        cell *x = &g->slot[i];
        if (x->head < 0)
            return x;
        if (x->tag != tag)
            continue;
        int64_t hc[3];
        double frac[3];
        cell_of(g->verts[x->head], g->w, hc, frac);
        if (hc[0] == c[0] && hc[1] == c[1] && hc[2] == c[2])
            return x;
    }
}

/* 1 when *cancel (may be NULL) is set, read at every 4,096th step i of a
 * loop whose steps each take well under a microsecond. */
static int poll_cancel(pd_cancel_flag *cancel, size_t i)
{
    return cancel && i % 4096 == 4095 && atomic_load_explicit(cancel, memory_order_relaxed);
}

/* Representatives by grid: rep[i] for every vertex. 0 if the coordinates are
 * too large for cells of this size (the caller falls back to exact bits). */
static pd_status grid_reps(const pd_mesh *m, double tol, int *rep, int *usable,
                           pd_cancel_flag *cancel)
{
    /* Cells four times tol wide: two points within tol differ by at most a
     * quarter of a cell (plus CELL_SLACK) on each axis, so a neighbouring
     * cell can hold a match only for a point within a quarter cell of the
     * side they share: 3.4 cells looked into on average, where cells twice
     * tol wide took the neighbour on the nearer side always, 8. Each look
     * is a cache miss on a large mesh. Points within a cell are
     * representatives, more than tol apart, so a cell holds few. */
    double w = 4.0 * tol;
    *usable = 0;
    for (int i = 0; i < m->nverts; i++) {
        pd_vec3 v = m->verts[i];
        if (!(fabs(v.x / w) < CELL_LIMIT && fabs(v.y / w) < CELL_LIMIT &&
              fabs(v.z / w) < CELL_LIMIT))
            return PD_OK;
    }
    *usable = 1;
    grid g;
    size_t cap = 64;
    while (cap / 2 < (size_t)m->nverts)
        cap *= 2;
    g.slot = malloc(cap * sizeof *g.slot);
    g.next = malloc(((size_t)m->nverts + 1) * sizeof *g.next);
    g.mask = cap - 1;
    g.verts = m->verts;
    g.w = w;
    if (!g.slot || !g.next) {
        free(g.slot);
        free(g.next);
        return PD_ERR_NOMEM;
    }
    for (size_t k = 0; k < cap; k++)
        g.slot[k].head = -1;
    for (int i = 0; i < m->nverts; i++) {
        if (poll_cancel(cancel, i)) {
            free(g.slot);
            free(g.next);
            return PD_ERR_CANCELLED;
        }
        pd_vec3 v = m->verts[i];
        int64_t c[3];
        double frac[3];
        int lo[3], hi[3];
        cell_of(v, w, c, frac);
        for (int k = 0; k < 3; k++) {
            lo[k] = frac[k] < 0.25 + CELL_SLACK ? -1 : 0;
            hi[k] = frac[k] > 0.75 - CELL_SLACK ? 1 : 0;
        }
        int best = -1;
        for (int dx = lo[0]; dx <= hi[0]; dx++)
            for (int dy = lo[1]; dy <= hi[1]; dy++)
                for (int dz = lo[2]; dz <= hi[2]; dz++) {
                    int64_t nc[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
                    for (int r = find_cell(&g, nc)->head; r >= 0; r = g.next[r])
                        if ((best < 0 || r < best) && v3_dist(m->verts[r], v) <= tol)
                            best = r;
                }
        if (best >= 0) {
            rep[i] = best;
            continue;
        }
        rep[i] = i;
        cell *slot = find_cell(&g, c);
        if (slot->head < 0)
            slot->tag = (uint32_t)(cell_hash(c) >> 32);
        g.next[i] = slot->head;
        slot->head = i;
    }
    free(g.slot);
    free(g.next);
    return PD_OK;
}

/* Representatives by exact bit pattern only. */
static pd_status exact_reps(const pd_mesh *m, int *rep, pd_cancel_flag *cancel)
{
    pd_vmap map;
    if (pd_vmap_init(&map, (size_t)m->nverts) != PD_OK)
        return PD_ERR_NOMEM;
    for (int i = 0; i < m->nverts; i++)
        if (poll_cancel(cancel, i)) {
            pd_vmap_free(&map);
            return PD_ERR_CANCELLED;
        } else if ((rep[i] = pd_vmap_find_or_add(&map, m->verts, i)) < 0) {
            pd_vmap_free(&map);
            return PD_ERR_NOMEM;
        }
    pd_vmap_free(&map);
    return PD_OK;
}

pd_status pd_mesh_weld(pd_mesh *mesh, double tol, int *nmerged)
{
    return pd_mesh_weld_cancel(mesh, tol, nmerged, NULL);
}

pd_status pd_mesh_weld_cancel(pd_mesh *mesh, double tol, int *nmerged, pd_cancel_flag *cancel)
{
    pd_status st = pd_mesh_validate(mesh, "weld", NULL);
    if (st != PD_OK)
        return st;
    if (!(tol >= 0.0 && isfinite(tol)))
        return PD_ERR_USAGE;
    size_t nv = (size_t)mesh->nverts, nt = (size_t)mesh->ntris;
    /* Everything is built aside and swapped in at the end, so a failure
     * leaves the mesh as it was. */
    int *rep = malloc((nv + 1) * sizeof *rep);
    int *newidx = malloc((nv + 1) * sizeof *newidx);
    if (!rep || !newidx) {
        free(rep);
        free(newidx);
        return PD_ERR_NOMEM;
    }
    int usable = 0;
    /* tol == 0 asks for bit-identical merging only. */
    if (tol > 0.0)
        st = grid_reps(mesh, tol, rep, &usable, cancel);
    if (st == PD_OK && !usable)
        st = exact_reps(mesh, rep, cancel);
    int (*tris)[3] = NULL;
    pd_vec3 *verts = NULL;
    if (st == PD_OK) {
        tris = malloc((nt + 1) * sizeof *tris);
        if (!tris)
            st = PD_ERR_NOMEM;
    }
    if (st != PD_OK) {
        free(rep);
        free(newidx);
        return st;
    }
    /* Keep triangles whose corners stay distinct; number the vertices they
     * use in input order. */
    int ntris = 0, nverts = 0;
    for (size_t i = 0; i < nv; i++)
        newidx[i] = -1;
    for (size_t t = 0; t < nt; t++) {
        if (poll_cancel(cancel, t)) {
            free(rep);
            free(newidx);
            free(tris);
            return PD_ERR_CANCELLED;
        }
        int a = rep[mesh->tris[t][0]], b = rep[mesh->tris[t][1]], c = rep[mesh->tris[t][2]];
        if (a == b || b == c || a == c)
            continue;
        tris[ntris][0] = a;
        tris[ntris][1] = b;
        tris[ntris][2] = c;
        newidx[a] = newidx[b] = newidx[c] = 0;
        ntris++;
    }
    for (size_t i = 0; i < nv; i++)
        if (newidx[i] == 0)
            newidx[i] = nverts++;
    verts = malloc(((size_t)nverts + 1) * sizeof *verts);
    if (!verts) {
        free(rep);
        free(newidx);
        free(tris);
        return PD_ERR_NOMEM;
    }
    for (size_t i = 0; i < nv; i++)
        if (newidx[i] >= 0)
            verts[newidx[i]] = mesh->verts[i];
    for (int t = 0; t < ntris; t++)
        for (int k = 0; k < 3; k++)
            tris[t][k] = newidx[tris[t][k]];
    if (nmerged)
        *nmerged = mesh->nverts - nverts;
    free(mesh->verts);
    free(mesh->tris);
    mesh->verts = verts;
    mesh->tris = tris;
    mesh->nverts = nverts;
    mesh->ntris = ntris;
    free(rep);
    free(newidx);
    return PD_OK;
}
