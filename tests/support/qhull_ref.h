/* qhull_ref.h: the reference convex hull, through libqhull_r (tests and
 * benchmark only; never linked into libposedrop).
 *
 * qhull runs with its default options ("qhull": facets merged where round-off
 * makes them coplanar or non-convex, no triangulation), prints nothing, and
 * its facets are copied out as unit outward normals and offsets so a test can
 * match them one by one against pd_hull's. */
#ifndef PD_TEST_QHULL_REF_H
#define PD_TEST_QHULL_REF_H

#include "posedrop/types.h"

typedef struct {
    int nfacets;
    double volume;
    int nverts;
    pd_vec3 *normal; /* nfacets unit outward normals */
    double *offset;  /* dot(normal, x) == offset on facet */
} qhull_ref;

/* 0 on success; nonzero when qhull fails (degenerate input, no memory).
 * On failure q holds no memory. */
int qhull_ref_build(const pd_vec3 *pts, int n, qhull_ref *q);
void qhull_ref_free(qhull_ref *q);

#endif
