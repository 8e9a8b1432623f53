/* same_file.c: no output of a run may land on one of its inputs or on
 * another of its outputs. posedrop, posedrop merge and posedrop-mpi all check
 * their files here, at the start of cli_run, before anything is read for the
 * run or written.
 *
 * Two names are the same file when they reach the same device and inode (a
 * hard link, a symbolic link, "./x" and "x"); a name that does not exist yet
 * is compared by its resolved directory and its last component, which is
 * where the output would be created (out_open renames onto that name). Only
 * regular files and names not yet taken are compared: writing to a device or
 * a pipe (/dev/null, /dev/stdout) destroys no file, and such a name may be
 * given to more than one output. Standard output counts as an output when it
 * is a regular file, so that a run redirected onto its own --trials file, or
 * a merge onto one of its shards, is refused too. */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "cli/cli.h"

typedef struct {
    int kind;       /* 0: not compared, 1: an existing regular file, 2: a name not yet taken */
    dev_t dev;
    ino_t ino;
    char *where;    /* kind 2: the resolved directory and the last component */
} file_id;

static void identify(const char *path, file_id *id)
{
    memset(id, 0, sizeof *id);
    struct stat sb;
    if (stat(path, &sb) == 0) {
        if (S_ISREG(sb.st_mode)) {
            id->kind = 1;
            id->dev = sb.st_dev;
            id->ino = sb.st_ino;
        }
        return;
    }
    /* A dangling symbolic link is replaced by the output, not followed:
     * its own name is where the file goes, as for any name not taken. */
    if (errno != ENOENT || !*path)
        return;
    const char *slash = strrchr(path, '/');
    const char *base = slash ? slash + 1 : path;
    if (!*base)
        return;
    char dir[PATH_MAX];
    int dirlen = slash ? (slash == path ? 1 : (int)(slash - path)) : 1;
    snprintf(dir, sizeof dir, "%.*s", dirlen, slash ? path : ".");
    char *real = realpath(dir, NULL);
    if (!real) /* no such directory: the output fails to open, by its own message */
        return;
    size_t size = strlen(real) + strlen(base) + 2;
    id->where = malloc(size);
    if (id->where) {
        snprintf(id->where, size, "%s/%s", real, base);
        id->kind = 2;
    }
    free(real);
}

static int same(const file_id *x, const file_id *y)
{
    if (x->kind != y->kind || x->kind == 0)
        return 0;
    return x->kind == 1 ? x->dev == y->dev && x->ino == y->ino : strcmp(x->where, y->where) == 0;
}

int cli_files_apart(const cli_file *files, int n)
{
    /* One more: standard output. */
    cli_file *all = malloc(sizeof *all * (size_t)(n + 1));
    file_id *ids = calloc((size_t)n + 1, sizeof *ids);
    if (!all || !ids) {
        free(all);
        free(ids);
        fprintf(stderr, "%s: out of memory\n", prog);
        return 0;
    }
    memcpy(all, files, sizeof *all * (size_t)n);
    for (int i = 0; i < n; i++)
        identify(files[i].path, &ids[i]);
    struct stat sb;
    if (fstat(STDOUT_FILENO, &sb) == 0 && S_ISREG(sb.st_mode)) {
        all[n] = (cli_file){"standard output", "", 1, 0};
        ids[n] = (file_id){1, sb.st_dev, sb.st_ino, NULL};
        n++;
    }
    int ok = 1;
    for (int i = 0; ok && i < n; i++)
        for (int j = 0; ok && j < n; j++) {
            /* Each pair once, and an output against inputs and other outputs only. */
            if (j == i || !all[i].output || (all[j].output && j < i) || !same(&ids[i], &ids[j]))
                continue;
            const cli_file *o = &all[i], *x = &all[j];
            fprintf(stderr, "%s: %s%s%s%s is the same file as %s%s%s%s: %s\n", prog,
                    o->option ? "--" : "", o->what, *o->path ? " " : "", o->path,
                    x->option ? "--" : "", x->what, *x->path ? " " : "", x->path,
                    x->output ? "two outputs may not share a file"
                              : "an output may not overwrite an input");
            ok = 0;
        }
    for (int i = 0; i < n; i++)
        free(ids[i].where);
    free(ids);
    free(all);
    return ok;
}
