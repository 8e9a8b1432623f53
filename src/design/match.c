/* match.c: the poses of a changed part, named by the part as given. */
#include <stdlib.h>
#include "design/design_match.h"

pd_status design_pose_map(const pd_part *base, const pd_static_result *bres, const pd_part *part,
                          const pd_static_result *res, int *map)
{
    int *mark = calloc((size_t)base->mesh->nverts, sizeof *mark);
    if (!mark)
        return PD_ERR_NOMEM;
    for (int j = 0; j < res->nposes; j++)
        map[j] = -1;
    for (int i = 0; i < bres->nposes; i++) {
        int g = design_match_facet(base, bres->poses[i].facet, part, mark);
        for (int j = 0; g >= 0 && j < res->nposes; j++)
            if (res->poses[j].facet == g)
                map[j] = i;
    }
    free(mark);
    return PD_OK;
}

double design_pose_p(const pd_static_result *res, const int *map, int i, int which)
{
    double p = 0.0;
    for (int j = 0; j < res->nposes; j++)
        if (map[j] == i)
            p += which ? res->poses[j].p_pqs : res->poses[j].p_qs;
    return p;
}
