/* cli.h: what the run (command.c) builds on, below it: run.c (or run_mpi.c
 * in posedrop-mpi) runs the drops; shard.c writes, reads and sums shards;
 * json_out.c prints --format json; progress.c draws the progress line;
 * sha256.c hashes the part file; plausible.c warns of a part or drop height
 * out of scale; fragile.c of a stationary estimate that rests on few drops;
 * signals.c catches SIGINT and SIGTERM; same_file.c keeps outputs off
 * inputs. The commands above it: cli.c (posedrop's options), merge.c
 * (posedrop merge). */
#ifndef PD_CLI_CLI_H
#define PD_CLI_CLI_H

#include <stdio.h>
#include "cli/args.h"

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
double cli_wall_seconds(void); /* a monotonic clock, s, for timings (command.c) */

/* A side file written to a temporary beside its path and renamed onto it
 * once the run's every output is complete (command.c): out_open makes it
 * ready before any work (0 and a message when it cannot be written),
 * out_close closes it (0 and a message on a write error, the file then
 * dropped), out_place puts a closed file in place, out_place_all each of n
 * that was opened (after stdout is written in full), out_abort drops it. */
typedef struct {
    const char *path;
    char *target; /* where the temporary is renamed to (a symbolic link resolved) */
    char *tmp;    /* NULL when path is written directly */
    FILE *f;
} out_file;
/* A failure to read or build the part of path on stderr, naming the file
 * once: the library's message already starts with it when it says where. */
void cli_say_failure(const char *path, pd_status st, const pd_diag *diag);
int out_open(out_file *o, const char *path);
int out_close(out_file *o);
int out_place(out_file *o);
int out_place_all(out_file *const *files, int n);
void out_abort(out_file *o);

/* fit_cmd.c: the fit subcommand (parses its own options). */
int cli_fit(int argc, char **argv);

/* design_cmd.c: the design subcommand (parses its own options). */
int cli_design(int argc, char **argv);

/* shard.c: --shard K/N parses into a->sim; the shard's leading comment lines;
 * the shards of a merge read and checked into a->scene, a->sim and the
 * part's path and SHA-256 (shard_load; shard_unload frees them), and summed
 * by merge_shards when the run comes to its drops. */
int shard_parse(const char *text, pd_sim_options *sim);
int shard_write_identity(FILE *out, const cli_args *a, const pd_sim_result *sim);
int shard_load(char **files, int nfiles, cli_args *a, char *path, size_t path_size,
               char sha[65]);
void shard_unload(void);
pd_status merge_shards(const pd_static_result *res, cli_args *a, pd_sim_result **sum,
                       pd_diag *diag);

/* json_out.c: one JSON document for the poses (or classes) and the run. */
/* xe: --crosscheck's engines (NULL: none), their columns added to the rows. */
void json_print(FILE *out, const cli_args *a, const pd_part *part, const pd_static_result *res,
                const pd_sim_result *sim, const int *class_of, int nclasses,
                const viz_engines *xe, double wall_s);

/* signals.c: signals_install, the first thing main does, catches SIGINT and
 * SIGTERM (and unblocks them). signals_catch makes them set options->cancel:
 * the drops in flight finish and the result is marked partial;
 * cli_interrupt_code is then 128 + the signal's number (130, 143).
 * signals_caught: whether one arrived in this process. */
void signals_install(void);
void signals_catch(pd_sim_options *options);
void signals_catch_fit(pd_fit_options *options);
int signals_caught(void);
/* The same for the static estimate: reading, the part build, QS and PQS
 * return PD_ERR_CANCELLED soon after a signal. */
void signals_catch_static(cli_args *a);

/* progress.c: when stderr is a terminal, options->progress draws a line. */
void progress_attach(pd_sim_options *options);
void progress_clear(void);
/* --progress: the lines are drawn even when stderr is not a terminal. */
void progress_force(void);
/* The static estimate's line: once it has run STATIC_QUIET_S, a line on
 * stderr names the stage under way and the seconds so far, redrawn by a
 * thread of its own (a stage may be one long call); stage_begin names the
 * command's own stages, and the part build's come through
 * options->stage. static_progress_end clears the line. */
void static_progress_begin(pd_part_options *options);
void static_progress_stage(const char *name);
void static_progress_end(void);

/* plausible.c: warns on stderr when the part's size, or the drop height
 * against it, suggests a unit mistaken (a file in millimetres read as
 * metres). plausible_warn_size: the size's warning alone
 * (pd_units_plausible), for posedrop fit's parts too; 1 when it warned. */
void plausible_warn(const cli_args *a, const pd_part *part);
int plausible_warn_size(const char *path, double size, pd_units units);

/* same_file.c: 1 when no output is the same file as an input or as another
 * output (standard output included when it is a regular file); otherwise 0,
 * with a message naming both and the file. */
int cli_files_apart(const cli_file *files, int n);

/* fragile.c: the warnings of a stationary run whose long run rests on its
 * first drops (several closed classes, or near traps), said without
 * --verbose. */
void fragile_warn(const char *path, const pd_sim_result *sim);

/* sha256.c: the file's SHA-256 as 64 hex digits; 0 with errno set on a read
 * error (EPIPE: a named pipe that gave nothing, its content read already). */
int sha256_file(const char *path, char hex[65]);

#endif
