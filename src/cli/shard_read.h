/* shard_read.h: reading one shard file of posedrop merge (shard.c sums
 * them), apart so that the fuzz target (tests/support/fuzz_targets.c) reads
 * shards as merge does. */
#ifndef PD_CLI_SHARD_READ_H
#define PD_CLI_SHARD_READ_H

#include <stddef.h>

typedef struct {
    const char *file;
    char *identity;  /* line 1 after "shard=K/N" */
    char *version;
    int k, n;        /* shard k (1-based) of n */
    long collisions, energy_gain, fallbacks;
    int nposes;
    long drops, unsettled;
    int partial;
    long *count, *first, *to; /* to: nposes * nposes, NULL unless stationary */
} shard_file;

/* Reads file into s (shard_file_clear frees it, also after a failure): 1,
 * or 0 with one message on stderr naming the file and line. */
int shard_read(const char *file, shard_file *s);
void shard_file_clear(shard_file *s);

/* "PROG: FILE:LINE: WHAT" (no line when line is 0) on stderr; 0. */
int shard_fail(const char *file, int line, const char *what);

/* The value of key=... in a line of words, copied into buf (size bytes);
 * NULL if absent or longer. */
const char *shard_find_word(const char *line, const char *key, char *buf, size_t size);

#endif
