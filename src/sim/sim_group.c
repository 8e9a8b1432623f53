/* sim_group.c: a dynamic result summed over pose classes (pd_sim_result_grouped,
 * posedrop/symmetry.h): counts and Wilson intervals per class, and for a
 * stationary run the long-run distribution of the pose chain summed. */
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/hash.h"
#include "base/stats.h"
#include "posedrop/symmetry.h"
#include "sim/markov.h"

pd_status pd_sim_result_grouped(const pd_sim_result *sim, const int *class_of, int nclasses,
                                pd_sim_result **grouped, pd_diag *diag)
{
    if (!sim || !class_of || !grouped)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_grouped: NULL %s",
                       !sim ? "sim" : !class_of ? "class_of" : "grouped");
    if (sim->nposes < 0 || (sim->nposes > 0 && !sim->count) || !sim->first_count != !sim->transitions)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_grouped: the result has not the arrays "
                       "of its %d poses", sim->nposes);
    if (sim->chain_class_of)
        return pd_fail(diag, PD_ERR_USAGE, "pd_sim_result_grouped: the result's chain is over "
                       "classes already (stationary_by_class)");
    /* At most a class per pose: more would only be empty classes, and a
     * count of the chain's class-to-class transitions for each pair. */
    if (nclasses < 0 || nclasses > sim->nposes || (nclasses == 0 && sim->nposes > 0))
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
    /* Another table of outcomes: no shard of the ungrouped run adds to it. */
    pd_hash h;
    pd_hash_init(&h, sim->run_fingerprint);
    pd_hash_ints(&h, class_of, sim->nposes);
    g->run_fingerprint = h.h;
    g->trials = NULL;
    g->added = NULL;
    g->added_nshards = 0;
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
