/* run.c: the drops of one process (posedrop; posedrop-mpi has run_mpi.c). */
#include <string.h>
#include <time.h>
#include "cli/cli.h"

void cli_start(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
}

int cli_end(int code)
{
    return code;
}

int cli_writer(void)
{
    return 1;
}

int cli_any(int mine)
{
    return mine;
}

double cli_cpu_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

pd_status cli_simulate(const pd_part *part, const pd_static_result *res, cli_args *a,
                       pd_sim_result **sim, pd_diag *diag)
{
    if (a->merge)
        return merge_shards(res, a, sim, diag);
    signals_catch(&a->sim);
    progress_attach(&a->sim);
    pd_status st = pd_sim_run(part, res, &a->scene, &a->sim, sim, diag);
    progress_clear();
    return st;
}
