/* signals.c: a long run stopped by SIGINT (Ctrl-C) or SIGTERM (a batch
 * system's time limit, kill) still prints the drops done, marked partial. */
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

void signals_catch(pd_sim_options *options)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    options->cancel = &caught;
}

int cli_interrupt_code(void)
{
    int sig = atomic_load(&caught);
    return 128 + (sig ? sig : SIGINT);
}
