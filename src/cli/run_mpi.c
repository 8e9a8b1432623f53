/* run_mpi.c: posedrop-mpi, the drops of one run spread over MPI ranks.
 *
 * Rank r of R runs shard r of R (pd_shard_of: drop i on rank i mod R), so
 * every drop keeps its index and its random stream; the counts are summed on
 * rank 0 (MPI_Reduce of integers, exact in any order), which alone prints,
 * through the code the single process prints with: the same bytes. Ranks
 * other than 0 write nothing (their stdout and stderr go to /dev/null). */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "cli/cli.h"

static int rank, nranks;
static double cpu_total = -1.0; /* all ranks' CPU seconds, once reduced */

void cli_start(int *argc, char ***argv)
{
    MPI_Init(argc, argv);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &nranks);
    if (rank > 0 && (!freopen("/dev/null", "w", stdout) || !freopen("/dev/null", "w", stderr)))
        MPI_Abort(MPI_COMM_WORLD, EXIT_INTERNAL);
}

int cli_end(int code)
{
    MPI_Finalize();
    return code;
}

int cli_writer(void)
{
    return rank == 0;
}

int cli_any(int mine)
{
    int any = 0;
    mine = mine != 0;
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return any;
}

static double own_cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

double cli_cpu_seconds(void)
{
    return cpu_total >= 0 ? cpu_total + own_cpu_seconds() : own_cpu_seconds();
}

/* The counts as one array of longs: drops, unsettled (and how: time limit,
 * collision limit, failed), corrections, collisions, partial, then per pose
 * count, first and the chain's rows. */
static size_t pack(const pd_sim_result *r, long *v)
{
    size_t k = (size_t)r->nposes, n = 0;
    v[n++] = r->n;
    v[n++] = r->unsettled;
    v[n++] = r->time_limited;
    v[n++] = r->collision_limited;
    v[n++] = r->failed;
    v[n++] = r->energy_gain;
    v[n++] = r->fallbacks;
    v[n++] = r->collisions;
    v[n++] = r->partial;
    for (size_t i = 0; i < k; i++)
        v[n++] = r->count[i];
    for (size_t i = 0; r->transitions && i < k; i++)
        v[n++] = r->first_count[i];
    for (size_t i = 0; r->transitions && i < k * k; i++)
        v[n++] = r->transitions[i];
    return n;
}

static void unpack(pd_sim_result *r, const long *v)
{
    size_t k = (size_t)r->nposes, n = 0;
    r->n = v[n++];
    r->unsettled = v[n++];
    r->time_limited = v[n++];
    r->collision_limited = v[n++];
    r->failed = v[n++];
    r->energy_gain = v[n++];
    r->fallbacks = v[n++];
    r->collisions = v[n++];
    r->partial = v[n++] > 0;
    for (size_t i = 0; i < k; i++)
        r->count[i] = v[n++];
    for (size_t i = 0; r->transitions && i < k; i++)
        r->first_count[i] = v[n++];
    for (size_t i = 0; r->transitions && i < k * k; i++)
        r->transitions[i] = v[n++];
}

static pd_status refuse(pd_diag *diag, const char *what)
{
    snprintf(diag->message, sizeof diag->message, "posedrop-mpi on %d ranks: %s", nranks, what);
    return PD_ERR_USAGE;
}

pd_status cli_simulate(const pd_part *part, const pd_static_result *res, cli_args *a,
                       pd_sim_result **sim, pd_diag *diag)
{
    if (a->merge)
        return merge_shards(res, a, sim, diag);
    if (nranks > 1 && (a->sim.nshards || a->trials || a->sensitivity || a->trace))
        return refuse(diag, "--shard, --trials, --trace and --sensitivity need a single process "
                      "(mpirun -n 1)");
    if (nranks > 1 && (a->sim.ci_halfwidth > 0 || a->sim.effect_halfwidth > 0 ||
                       a->scene.initial == PD_INITIAL_BOOTSTRAP))
        return refuse(diag, "--ci, --effect and --initial bootstrap choose each batch of drops from the "
                      "outcomes before it, so they run in one process (mpirun -n 1, or posedrop "
                      "with -j threads)");
    signals_catch(&a->sim);
    if (rank == 0)
        progress_attach(&a->sim);
    pd_sim_options o = a->sim;
    if (nranks > 1) {
        o.nshards = nranks;
        o.shard = rank;
    }
    pd_sim_result *mine = NULL, *sum = NULL;
    pd_status st = pd_sim_run(part, res, &a->scene, &o, &mine, diag);
    progress_clear();
    /* Every rank learns whether any failed before the sums, so none waits
     * for a rank that gave up. */
    int failed = st != PD_OK, any = 0;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (any) {
        pd_sim_result_free(mine);
        if (st == PD_OK) {
            snprintf(diag->message, sizeof diag->message, "another rank failed");
            st = PD_ERR_INTERNAL;
        }
        return st;
    }
    if (nranks == 1) {
        *sim = mine;
        return PD_OK;
    }
    size_t k = (size_t)res->nposes, len = 9 + k + (mine->transitions ? k + k * k : 0);
    long *mine_v = malloc(sizeof *mine_v * len), *sum_v = malloc(sizeof *sum_v * len);
    int ok = mine_v && sum_v;
    MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (ok) {
        pack(mine, mine_v);
        MPI_Reduce(mine_v, sum_v, (int)len, MPI_LONG, MPI_SUM, 0, MPI_COMM_WORLD);
        double cpu = own_cpu_seconds(), cpu_sum = 0.0;
        MPI_Reduce(&cpu, &cpu_sum, 1, MPI_DOUBLE, MPI_SUM, 0, MPI_COMM_WORLD);
        /* Later CPU time of rank 0 (the printing) is added when asked. */
        cpu_total = rank == 0 ? cpu_sum - cpu : -1.0;
    }
    pd_sim_options whole = a->sim;
    whole.nshards = 0;
    if (!ok) {
        snprintf(diag->message, sizeof diag->message, "out of memory for the counts");
        st = PD_ERR_NOMEM;
    } else if (rank == 0 && (st = pd_sim_result_new(res, &a->scene, &whole, &sum, diag)) ==
                                PD_OK) {
        unpack(sum, sum_v);
        sum->time_limit = mine->time_limit;
        st = pd_sim_result_finish(sum, diag);
    }
    free(mine_v);
    free(sum_v);
    pd_sim_result_free(mine);
    if (st != PD_OK) {
        pd_sim_result_free(sum);
        return st;
    }
    *sim = sum;
    return PD_OK;
}
