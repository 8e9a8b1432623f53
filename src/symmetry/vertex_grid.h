/* vertex_grid.h (private): the hull vertex nearest a point within a
 * tolerance, by a hash of grid cells (vertex_grid.c), and the hashing and
 * (key, index) sorting the symmetry search shares with it. */
#ifndef PD_VERTEX_GRID_H
#define PD_VERTEX_GRID_H

#include <stddef.h>
#include <stdint.h>
#include "posedrop/types.h"

/* Sorted as (key, index) pairs: qsort takes no user pointer in C11, and a
 * file-scope one would make the library unsafe to call from two threads. */
typedef struct {
    uint64_t key;
    int idx;
} pd_keyed;

int pd_keyed_cmp(const void *pa, const void *pb);

/* Open addressing: the slot of a key in a table of mask + 1 slots (a power
 * of two), and the table size that keeps n keys at most half full. */
size_t pd_hash_slot(uint64_t key, size_t mask);
size_t pd_hash_slots(size_t n);

typedef struct {
    double cell;
    int n;
    const pd_vec3 *w;
    uint64_t *key;     /* per vertex */
    int *sorted;       /* vertex indices by key */
    int *slot_first;   /* hash slot -> first position in sorted, -1 empty */
    size_t mask;
} pd_vgrid;

/* Indexes the n points w (kept by pointer, not copied) for lookups within
 * tol. 0: out of memory (g is then freed). */
int pd_vgrid_build(pd_vgrid *g, const pd_vec3 *w, int n, double tol);
void pd_vgrid_free(pd_vgrid *g);

/* The point other than skip nearest to x within tol, or -1; *dist receives
 * its distance (tol when there is none). */
int pd_vgrid_nearest(const pd_vgrid *g, pd_vec3 x, double tol, int skip, double *dist);

#endif
