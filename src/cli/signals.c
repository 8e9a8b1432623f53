/* signals.c: a long run stopped by SIGINT (Ctrl-C) or SIGTERM (a batch
 * system's time limit, kill) still prints the drops done, marked partial;
 * one that arrives before the drops start stops the run with nothing
 * printed. */
#include <signal.h>
#include <string.h>
#include "cli/cli.h"

/* The signal's number; the library reads it as its cancel flag (lock-free,
 * so a handler may store into it). */
static pd_cancel_flag caught;

static void on_signal(int sig)
{
    atomic_store(&caught, sig);
}

void signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* A parent may start the command with them blocked, one already
     * pending: taken now, it is caught like any later one. */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(SIG_UNBLOCK, &set, NULL);
}

void signals_catch(pd_sim_options *options)
{
    options->cancel = &caught;
}

void signals_catch_fit(pd_fit_options *options)
{
    options->cancel = &caught;
}

void signals_catch_static(cli_args *a)
{
    a->read.cancel = &caught;
    a->part.cancel = &caught;
    a->estimate.cancel = &caught;
}

int signals_caught(void)
{
    return atomic_load(&caught) != 0;
}

int cli_interrupt_code(void)
{
    int sig = atomic_load(&caught);
    return 128 + (sig ? sig : SIGINT);
}
