/* cli.h: what the files of the posedrop command share. cli.c parses the
 * options and prints CSV; run.c (or run_mpi.c in posedrop-mpi) runs the
 * drops; shard.c writes and merges shards; json_out.c prints --format json;
 * progress.c draws the progress line; sha256.c hashes the part file. */
#ifndef PD_CLI_CLI_H
#define PD_CLI_CLI_H

#include <stdio.h>
#include "viz/viz.h"
#include "posedrop/posedrop.h"

enum { EXIT_USAGE = 2, EXIT_INTERNAL = 1 };

extern const char *prog;

/* A file the run reads (an input) or writes (an output), with what names it
 * in messages: a long option's name (option 1: "trials" is shown "--trials")
 * or a role ("PART", "shard"). */
typedef struct {
    const char *what, *path;
    int output, option;
} cli_file;

typedef struct {
    const char *path, *trials, *transitions, *com_text;
    pd_mesh_read_options read;
    pd_part_options part;
    pd_static_options estimate;
    pd_scene scene;
    pd_sim_options sim;
    int dynamic, facets, group, verbose;
    const char *pictures[VIZ_KINDS]; /* --svg, --chart, --sphere, --report */
    const char *measured;
    const char *sensitivity;       /* --sensitivity FILE */
    int json;                      /* --format json */
    int argc;                      /* the command line, for the JSON metadata */
    char **argv;
    char **merge;                  /* posedrop merge: the shard files (NULL ended) */
    cli_file *files;               /* every file named, for cli_files_apart (owned) */
    int nfiles;
} cli_args;

/* The run after its options: read, estimate, drop (or merge), print. */
int cli_run(cli_args *a);

/* Axis-aligned normals come out with round-off components like 1e-17; print
 * them as 0 (and never as -0). */
double cli_clean(double x);

/* run.c / run_mpi.c. cli_start and cli_end wrap the whole program (MPI's
 * start and end); cli_simulate runs the drops (or sums the shards of a
 * merge); cli_writer says whether this process prints (MPI: rank 0 only);
 * cli_interrupt_code (signals.c) the exit code of a run stopped by a
 * signal. */
void cli_start(int *argc, char ***argv);
int cli_end(int code);
pd_status cli_simulate(const pd_part *part, const pd_static_result *res, cli_args *a,
                       pd_sim_result **sim, pd_diag *diag);
int cli_writer(void);
int cli_interrupt_code(void);
/* Whether mine is true in this process (MPI: in any rank), so that a
 * decision to stop that one rank makes (a signal, its standard output on an
 * input) stops them all together. */
int cli_any(int mine);
double cli_cpu_seconds(void); /* the CPU time of the run (MPI: all ranks) */

/* A side file written to a temporary beside its path and renamed onto it
 * once complete (cli.c): out_open makes it ready before any work (0 and a
 * message when it cannot be written), out_commit puts it in place (0 and a
 * message on a write error), out_abort drops it. */
typedef struct {
    const char *path;
    char *target; /* where the temporary is renamed to (a symbolic link resolved) */
    char *tmp;    /* NULL when path is written directly */
    FILE *f;
} out_file;
int out_open(out_file *o, const char *path);
int out_commit(out_file *o);
void out_abort(out_file *o);

/* fit.c: the fit subcommand (parses its own options). */
int cli_fit(int argc, char **argv);

/* shard.c: --shard K/N parses into a->sim; the shard's leading comment lines;
 * the merge subcommand (parses its own options, then cli_run). */
int shard_parse(const char *text, pd_sim_options *sim);
int shard_write_identity(FILE *out, const cli_args *a, const pd_sim_result *sim);
int cli_merge(int argc, char **argv);
pd_status merge_shards(const pd_static_result *res, cli_args *a, pd_sim_result **sum,
                       pd_diag *diag);

/* json_out.c: one JSON document for the poses (or classes) and the run. */
void json_print(FILE *out, const cli_args *a, const pd_part *part, const pd_static_result *res,
                const pd_sim_result *sim, const int *class_of, int nclasses, double wall_s);

/* signals.c: signals_install, the first thing main does, catches SIGINT and
 * SIGTERM (and unblocks them). signals_catch makes them set options->cancel:
 * the drops in flight finish and the result is marked partial;
 * cli_interrupt_code is then 128 + the signal's number (130, 143).
 * signals_caught: whether one arrived in this process. */
void signals_install(void);
void signals_catch(pd_sim_options *options);
int signals_caught(void);

/* progress.c: when stderr is a terminal, options->progress draws a line. */
void progress_attach(pd_sim_options *options);
void progress_clear(void);

/* same_file.c: 1 when no output is the same file as an input or as another
 * output (standard output included when it is a regular file); otherwise 0,
 * with a message naming both and the file. */
int cli_files_apart(const cli_file *files, int n);

/* fragile.c: the warnings of a stationary run whose long run rests on its
 * first drops (several closed classes, or near traps), said without
 * --verbose. */
void fragile_warn(const char *path, const pd_sim_result *sim);

/* sha256.c: the file's SHA-256 as 64 hex digits; 0 with errno set on a read
 * error. */
int sha256_file(const char *path, char hex[65]);

#endif
