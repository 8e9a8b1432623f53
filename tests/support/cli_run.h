/* cli_run.h: running the built posedrop command from a test, as a user
 * would (tests/unit/test_cli.c, test_batch.c). */
#ifndef PD_TEST_CLI_RUN_H
#define PD_TEST_CLI_RUN_H

#include "cli_paths.h"
#include "files.h" /* slurp */

/* A scratch directory of the suite (mkdtemp), where run_cmd keeps its
 * captures. */
extern char tmpdir[64];

int write_file(const char *path, const char *text);

/* Runs "posedrop ARGS" (or any shell command when raw), returns the exit code
 * and the captured stdout and stderr (caller frees). */
int run_cmd(const char *cmd, int raw, char **out, char **err);
int run(const char *args, char **out, char **err);

/* A failed run: the exit code, nothing on stdout, and stderr mentions what. */
void expect_failure(const char *args, int code, const char *mention);

#endif
