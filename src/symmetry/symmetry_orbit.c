/* symmetry_orbit.c: the rotations generated so far in the symmetry search,
 * as the orbit of the reference pair (a, b) under the generators' vertex
 * permutations (see symmetry_search.c). */
#include <stdlib.h>
#include <string.h>
#include "symmetry/symmetry_orbit.h"
#include "symmetry/vertex_grid.h"

void pd_orbit_free(pd_orbit *g)
{
    free(g->e);
    free(g->slot);
    for (int i = 0; i < g->ngen; i++)
        free(g->perm[i]);
    free(g->perm);
    free(g->err);
}

static size_t pair_slot(const pd_orbit *g, int x, int y)
{
    return pd_hash_slot((uint64_t)x * (uint64_t)g->nv + (uint64_t)y, g->mask);
}

int pd_orbit_find(const pd_orbit *g, int x, int y)
{
    if (!g->slot)
        return -1;
    for (size_t s = pair_slot(g, x, y); g->slot[s] >= 0; s = (s + 1) & g->mask)
        if (g->e[g->slot[s]].x == x && g->e[g->slot[s]].y == y)
            return g->slot[s];
    return -1;
}

/* Room for one more element: the element array and a hash at most half full. */
static int orbit_reserve(pd_orbit *g)
{
    if (g->n == g->cap) {
        int cap = g->cap ? 2 * g->cap : 64;
        pd_orbit_elt *e = realloc(g->e, sizeof *e * (size_t)cap);
        if (!e)
            return 0;
        g->e = e;
        g->cap = cap;
    }
    if (2 * (size_t)(g->n + 1) <= g->mask + 1)
        return 1;
    size_t nslots = pd_hash_slots((size_t)g->n + 1);
    int *slot = malloc(sizeof *slot * nslots);
    if (!slot)
        return 0;
    free(g->slot);
    g->slot = slot;
    g->mask = nslots - 1;
    for (size_t s = 0; s < nslots; s++)
        slot[s] = -1;
    for (int i = 0; i < g->n; i++) {
        size_t s = pair_slot(g, g->e[i].x, g->e[i].y);
        while (slot[s] >= 0)
            s = (s + 1) & g->mask;
        slot[s] = i;
    }
    return 1;
}

/* Adds the element (x, y) unless it is there. 0: out of memory. */
static int orbit_add(pd_orbit *g, int x, int y, int parent, int gen)
{
    if (pd_orbit_find(g, x, y) >= 0)
        return 1;
    if (!orbit_reserve(g))
        return 0;
    g->e[g->n] = (pd_orbit_elt){x, y, parent, gen};
    size_t s = pair_slot(g, x, y);
    while (g->slot[s] >= 0)
        s = (s + 1) & g->mask;
    g->slot[s] = g->n++;
    return 1;
}

int pd_orbit_init(pd_orbit *g, int nv, int a, int b)
{
    memset(g, 0, sizeof *g);
    g->nv = nv;
    return orbit_add(g, a, b, -1, -1);
}

/* A new generator (perm copied) and the orbit closed under it: elements
 * already there are closed under the older generators, so they get only
 * the new one; new elements get all. 0: out of memory; PD_ORBIT_TOO_LARGE: the
 * orbit outgrew every rotation group of the hull. A group of rotations
 * about a point is cyclic or dihedral (order at most twice the vertices
 * that one of its axes turns, so at most 2 nv) or one of the solids'
 * (at most 60); the permutations of checked rotations of a hull within the
 * tolerance of being symmetric still make one, but those of a hull at the
 * edge of the tolerance need not, and their products could run to nv^2
 * pairs: then the search is left to the exhaustive loop. */
int pd_orbit_add_generator(pd_orbit *g, const int *perm, double err)
{
    if (g->ngen == g->gencap) {
        int cap = g->gencap ? 2 * g->gencap : 8;
        int **p = realloc(g->perm, sizeof *p * (size_t)cap);
        if (p)
            g->perm = p;
        double *e = p ? realloc(g->err, sizeof *e * (size_t)cap) : NULL;
        if (!e)
            return 0;
        g->err = e;
        g->gencap = cap;
    }
    int *copy = malloc(sizeof *copy * (size_t)g->nv);
    if (!copy)
        return 0;
    memcpy(copy, perm, sizeof *copy * (size_t)g->nv);
    int k = g->ngen++;
    g->perm[k] = copy;
    g->err[k] = err;
    int old = g->n, most = 2 * g->nv > 60 ? 2 * g->nv : 60;
    for (int i = 0; i < g->n; i++)
        for (int h = i < old ? k : 0; h <= k; h++) {
            int x = g->perm[h][g->e[i].x], y = g->perm[h][g->e[i].y];
            if (!orbit_add(g, x, y, i, h))
                return 0;
            if (g->n > most)
                return PD_ORBIT_TOO_LARGE;
        }
    return 1;
}
