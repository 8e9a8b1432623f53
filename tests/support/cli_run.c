/* cli_run.c: running the built posedrop command from a test (cli_run.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include "check.h"
#include "cli_run.h"
#include "files.h"

int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fputs(text, f);
    return fclose(f) == 0;
}

char tmpdir[64];

/* Runs "posedrop ARGS" (or any shell command when raw), returns the exit code
 * and the captured stdout and stderr (caller frees). */
int run_cmd(const char *cmd, int raw, char **out, char **err)
{
    char line[2048], outp[128], errp[128];
    snprintf(outp, sizeof outp, "%s/out", tmpdir);
    snprintf(errp, sizeof errp, "%s/err", tmpdir);
    snprintf(line, sizeof line, "%s %s >%s 2>%s </dev/null", raw ? "" : PD_CLI_PATH, cmd, outp,
             errp);
    int status = system(line);
    *out = slurp(outp);
    *err = slurp(errp);
    if (!*out)
        *out = calloc(1, 1);
    if (!*err)
        *err = calloc(1, 1);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int run(const char *args, char **out, char **err) { return run_cmd(args, 0, out, err); }

/* A failed run: the exit code, nothing on stdout, and stderr mentions what. */
void expect_failure(const char *args, int code, const char *mention)
{
    char *out, *err;
    int rc = run(args, &out, &err);
    CHECK_INT(rc, code);
    CHECK_INT((int)strlen(out), 0);
    if (!strstr(err, mention))
        printf("     stderr of '%s' lacks '%s':\n     %s", args, mention, err);
    CHECK(strstr(err, mention) != NULL);
    free(out);
    free(err);
}

