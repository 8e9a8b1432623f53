/* signals.c: a long run stopped by SIGINT (Ctrl-C) or SIGTERM (a batch
 * system's time limit, kill) still prints the drops done, marked partial. */
#include <signal.h>
#include <string.h>
#include "cli/cli.h"

static volatile sig_atomic_t caught;

static void on_signal(int sig)
{
    caught = sig;
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
    return 128 + (caught ? (int)caught : SIGINT);
}
