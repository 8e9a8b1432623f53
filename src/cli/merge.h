/* merge.h: the merge subcommand (merge.c). */
#ifndef PD_CLI_MERGE_H
#define PD_CLI_MERGE_H

/* posedrop merge SHARD...: parses its own options, reads and checks the
 * shards (shard.c), then runs as the unsharded run would (cli_run). */
int cli_merge(int argc, char **argv);

#endif
