/* args.h: the command's arguments, and what every file of the command
 * shares (args.c): its name for messages, its exit codes. Parsed by the
 * posedrop command (cli.c) or its merge subcommand (merge.c), run by
 * cli_run (command.h). */
#ifndef PD_CLI_ARGS_H
#define PD_CLI_ARGS_H

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
    const char *path, *trials, *transitions, *trace, *com_text;
    pd_mesh_read_options read;
    pd_part_options part;
    pd_static_options estimate;
    pd_scene scene;
    pd_sim_options sim;
    int dynamic, facets, group, verbose;
    int crosscheck;                /* --crosscheck: every engine on the same releases */
    char scene_option[32];         /* the first scene option given ("--mu"), "" if none */
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

/* Axis-aligned normals come out with round-off components like 1e-17; print
 * them as 0 (and never as -0). */
double cli_clean(double x);

#endif
