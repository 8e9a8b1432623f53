/* vertex_grid.c: the hull vertex nearest a point, within a tolerance.
 *
 * A hash of grid cells of side 4 tol; a lookup visits the cells that meet the
 * cube of half-side tol around the point, 1.5 per axis on average (3.4 in
 * all, against 27 for a cell and all its neighbours). Coordinates are
 * relative to the centre and at most the size L, so cell indices stay below
 * L / (4 tol) = 2.5e4, well inside the 21 bits each gets in the key. */

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/vec3.h"
#include "symmetry/vertex_grid.h"

enum { KEY_BITS = 21 };

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

size_t pd_hash_slot(uint64_t key, size_t mask)
{
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return (size_t)key & mask;
}

size_t pd_hash_slots(size_t n)
{
    size_t nslots = 16;
    while (nslots < 2 * n)
        nslots *= 2;
    return nslots;
}


int pd_keyed_cmp(const void *pa, const void *pb)
{
    const pd_keyed *a = pa, *b = pb;
    return a->key < b->key ? -1 : a->key > b->key ? 1 : (a->idx > b->idx) - (a->idx < b->idx);
}

void pd_vgrid_free(pd_vgrid *g)
{
    free(g->key);
    free(g->sorted);
    free(g->slot_first);
    memset(g, 0, sizeof *g); /* a failed build frees, and its caller again */
}

int pd_vgrid_build(pd_vgrid *g, const pd_vec3 *w, int n, double tol)
{
    memset(g, 0, sizeof *g);
    g->cell = 4.0 * tol;
    g->n = n;
    g->w = w;
    size_t nslots = pd_hash_slots((size_t)n);
    g->mask = nslots - 1;
    g->key = malloc(sizeof *g->key * (size_t)n);
    g->sorted = malloc(sizeof *g->sorted * (size_t)n);
    g->slot_first = malloc(sizeof *g->slot_first * nslots);
    pd_keyed *tmp = malloc(sizeof *tmp * (size_t)n);
    if (!g->key || !g->sorted || !g->slot_first || !tmp) {
        free(tmp);
        pd_vgrid_free(g);
        return 0;
    }
    for (int i = 0; i < n; i++) {
        g->key[i] = pack(cell_of(w[i].x, g->cell), cell_of(w[i].y, g->cell),
                         cell_of(w[i].z, g->cell));
        tmp[i].key = g->key[i];
        tmp[i].idx = i;
    }
    qsort(tmp, (size_t)n, sizeof *tmp, pd_keyed_cmp);
    for (int i = 0; i < n; i++)
        g->sorted[i] = tmp[i].idx;
    free(tmp);
    for (size_t s = 0; s < nslots; s++)
        g->slot_first[s] = -1;
    for (int p = 0; p < n; p++) {
        uint64_t k = g->key[g->sorted[p]];
        if (p > 0 && g->key[g->sorted[p - 1]] == k)
            continue;
        size_t s = pd_hash_slot(k, g->mask);
        while (g->slot_first[s] >= 0)
            s = (s + 1) & g->mask;
        g->slot_first[s] = p;
    }
    return 1;
}

/* The vertex other than skip nearest to x within tol, or -1; *dist receives
 * its distance (tol when there is none). */
int pd_vgrid_nearest(const pd_vgrid *g, pd_vec3 x, double tol, int skip, double *dist)
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
                size_t s = pd_hash_slot(k, g->mask);
                int p = -1;
                for (; g->slot_first[s] >= 0; s = (s + 1) & g->mask)
                    if (g->key[g->sorted[g->slot_first[s]]] == k) {
                        p = g->slot_first[s];
                        break;
                    }
                for (; p >= 0 && p < g->n && g->key[g->sorted[p]] == k; p++) {
                    int v = g->sorted[p];
                    double d = v3_dist(g->w[v], x);
                    if (v != skip && d <= best_d) {
                        best_d = d;
                        best = v;
                    }
                }
            }
    *dist = best_d;
    return best;
}
