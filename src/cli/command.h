/* command.h: the run after its options (command.c), below the commands
 * that parse them: posedrop (cli.c) and posedrop merge (merge.c). */
#ifndef PD_CLI_COMMAND_H
#define PD_CLI_COMMAND_H

#include "cli/args.h"

/* The run after its options: read, estimate, drop (or merge), print. */
int cli_run(cli_args *a);

#endif
