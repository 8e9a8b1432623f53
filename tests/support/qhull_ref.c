/* qhull_ref.c: see qhull_ref.h. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "libqhull_r/qhull_ra.h"
#include "qhull_ref.h"

int qhull_ref_build(const pd_vec3 *pts, int n, qhull_ref *q)
{
    memset(q, 0, sizeof *q);
    /* qhull writes its error reports to errfile: a sink, so tests of
     * degenerate input stay quiet. */
    FILE *sink = fopen("/dev/null", "w");
    if (!sink)
        return -1;
    coordT *coords = malloc(sizeof *coords * 3 * (size_t)(n > 0 ? n : 1));
    if (!coords) {
        fclose(sink);
        return -1;
    }
    for (int i = 0; i < n; i++) {
        coords[3 * i] = pts[i].x;
        coords[3 * i + 1] = pts[i].y;
        coords[3 * i + 2] = pts[i].z;
    }
    qhT qh_qh;
    qhT *qh = &qh_qh;
    qh_zero(qh, sink);
    char cmd[] = "qhull";
    int rc = qh_new_qhull(qh, 3, n, coords, False, cmd, NULL, sink);
    if (rc == 0) {
        qh_getarea(qh, qh->facet_list);
        q->volume = qh->totvol;
        q->nverts = qh->num_vertices;
        int nf = 0;
        facetT *facet;
        FORALLfacets
            nf++;
        q->normal = malloc(sizeof *q->normal * (size_t)nf);
        q->offset = malloc(sizeof *q->offset * (size_t)nf);
        if (!q->normal || !q->offset) {
            rc = -1;
        } else {
            int k = 0;
            FORALLfacets {
                /* qhull: normal . x + offset == 0 on the facet */
                q->normal[k].x = facet->normal[0];
                q->normal[k].y = facet->normal[1];
                q->normal[k].z = facet->normal[2];
                q->offset[k] = -facet->offset;
                k++;
            }
            q->nfacets = nf;
        }
    }
    qh_freeqhull(qh, !qh_ALL);
    int curlong, totlong;
    qh_memfreeshort(qh, &curlong, &totlong);
    free(coords);
    fclose(sink);
    if (rc != 0) {
        qhull_ref_free(q);
        return rc;
    }
    return 0;
}

void qhull_ref_free(qhull_ref *q)
{
    free(q->normal);
    free(q->offset);
    memset(q, 0, sizeof *q);
}
