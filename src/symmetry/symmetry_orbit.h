/* symmetry_orbit.h (private): the rotations generated so far in the
 * symmetry search, each named by the images (x, y) of the two reference
 * vertices: the orbit of (a, b) under the generators' vertex permutations,
 * with the tree of products that reached each element. */
#ifndef PD_SYMMETRY_ORBIT_H
#define PD_SYMMETRY_ORBIT_H

#include <stddef.h>

typedef struct {
    int x, y;         /* the images of a and b */
    int parent, gen;  /* generator gen times element parent (-1, -1: the identity) */
} pd_orbit_elt;

typedef struct {
    int nv;
    pd_orbit_elt *e;
    int n, cap;
    int *slot;        /* hash of (x, y) -> element, -1 empty */
    size_t mask;
    int **perm;       /* per generator: vertex images */
    double *err;      /* per generator: its check's largest error */
    int ngen, gencap;
} pd_orbit;

/* The orbit of the identity alone, (a, b), over nv vertices. 0: out of
 * memory. */
int pd_orbit_init(pd_orbit *g, int nv, int a, int b);
void pd_orbit_free(pd_orbit *g);

/* The element (x, y), or -1. */
int pd_orbit_find(const pd_orbit *g, int x, int y);

enum { PD_ORBIT_TOO_LARGE = 2 };

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
int pd_orbit_add_generator(pd_orbit *g, const int *perm, double err);

#endif
