/* fragile.c: says on stderr, without --verbose, when the long run of
 * --initial stationary rests on the first drops rather than on the chain:
 * the estimated chain has several closed classes (which one a part ends in
 * is decided by its first drop), or a pose keeps nearly every drop started
 * on it (a near trap: a part that reaches it seldom leaves, so its
 * long-run share rests on where first drops go and on the few drops that
 * left). Either way p rests on mu0, the uniform first drops' distribution,
 * more than the number of drops started resting suggests. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"

/* A pose keeping at least this share of the settled drops started on it is
 * a near trap: at 95% a part leaves it once in 20 drops, so the chain's long
 * run over a feeder's few passes is still mostly where it first landed. */
#define FRAGILE_KEEP 0.95

/* The row of pose i of the chain's counts. */
static const long *row(const pd_sim_result *sim, int i)
{
    return sim->transitions + (size_t)i * (size_t)sim->nposes;
}

/* reach[i * k + j]: pose j can follow pose i (i itself included) in the
 * estimated chain. */
static void reachability(const pd_sim_result *sim, unsigned char *reach)
{
    int k = sim->nposes;
    memset(reach, 0, (size_t)k * (size_t)k);
    for (int i = 0; i < k; i++) {
        unsigned char *r = reach + (size_t)i * (size_t)k;
        r[i] = 1;
        /* Grow the set until no count leads out of it. */
        for (int grew = 1; grew;) {
            grew = 0;
            for (int a = 0; a < k; a++)
                for (int b = 0; r[a] && b < k; b++)
                    if (!r[b] && row(sim, a)[b] > 0)
                        r[b] = grew = 1;
        }
    }
}

/* "3 4 5" into buf: the poses j with member(j). */
static void list_poses(char *buf, size_t size, const unsigned char *member, int k)
{
    size_t n = 0;
    buf[0] = '\0';
    for (int j = 0; j < k && n + 16 < size; j++)
        if (member[j])
            n += (size_t)snprintf(buf + n, size - n, "%s%d", n ? " " : "", j + 1);
}

void fragile_warn(const char *path, const pd_sim_result *sim)
{
    int k = sim->nposes;
    if (!sim->transitions || sim->closed_classes < 1 || k < 1)
        return;
    unsigned char *reach = malloc((size_t)k * (size_t)k), *member = malloc((size_t)k);
    char *list = malloc(4096);
    if (!reach || !member || !list) {
        free(reach);
        free(member);
        free(list);
        return;
    }
    reachability(sim, reach);
    if (sim->closed_classes > 1) {
        fprintf(stderr, "%s: %s: the long run is fragile: the estimated pose-to-pose chain has "
                        "%d closed classes reached from the first drops:", prog, path,
                sim->closed_classes);
        /* A closed class: poses reached from a first drop that reach back
         * everything they reach. Listed once, by its lowest pose. */
        int shown = 0;
        for (int i = 0; i < k; i++) {
            const unsigned char *ri = reach + (size_t)i * (size_t)k;
            int closed = 1, lowest = 1;
            for (int j = 0; j < k && closed; j++)
                if (ri[j] && !reach[(size_t)j * (size_t)k + (size_t)i])
                    closed = 0;
            for (int j = 0; j < i && closed; j++)
                if (ri[j])
                    lowest = 0;
            /* Reached from a first drop: some pose a uniform drop ended in
             * leads here. */
            int reached = 0;
            for (int j = 0; j < k && !reached; j++)
                reached = sim->first_count[j] > 0 && reach[(size_t)j * (size_t)k + (size_t)i];
            if (!closed || !lowest || !reached)
                continue;
            for (int j = 0; j < k; j++)
                member[j] = ri[j];
            list_poses(list, 4096, member, k);
            fprintf(stderr, "%s {pose%s %s}", shown++ ? "," : "", strchr(list, ' ') ? "s" : "",
                    list);
        }
        fprintf(stderr, ". A part stays in the class its first drop reaches, so p rests on the "
                        "%ld uniform first drops (mu0), not on the drops started resting; "
                        "--transitions FILE shows the chain\n", sim->first_drops);
    }
    memset(member, 0, (size_t)k);
    int traps = 0;
    for (int i = 0; i < k; i++) {
        long total = 0;
        for (int j = 0; j < k; j++)
            total += row(sim, i)[j];
        /* A pose that keeps every drop is a closed class of its own,
         * already named when there are several. */
        int named = sim->closed_classes > 1 && row(sim, i)[i] == total;
        if (total > 0 && !named && (double)row(sim, i)[i] >= FRAGILE_KEEP * (double)total && k > 1)
            member[i] = 1, traps++;
    }
    if (traps) {
        list_poses(list, 4096, member, k);
        fprintf(stderr, "%s: %s: the long run is fragile: pose%s %s keep%s at least %.0f%% of the "
                        "drops started on %s: a part that reaches %s seldom leaves, so p rests on "
                        "the %ld uniform first drops (mu0) and on the few drops that left\n",
                prog, path, traps > 1 ? "s" : "", list, traps > 1 ? "" : "s", 100 * FRAGILE_KEEP,
                traps > 1 ? "them" : "it", traps > 1 ? "one" : "it", sim->first_drops);
    }
    free(reach);
    free(member);
    free(list);
}
