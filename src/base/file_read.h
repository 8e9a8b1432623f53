/* file_read.h (private): opening a file the library reads (a part, a scene,
 * a measured table) without waiting for ever on a named pipe that no
 * program writes to. */
#ifndef PD_FILE_READ_H
#define PD_FILE_READ_H

#include <stddef.h>
#include <stdio.h>
#include "base/fail.h"

/* Opens path read-only. open(2) on a named pipe waits until a program opens
 * it for writing, for ever if none does; this opens without waiting and
 * then sets reads back to blocking, so that they wait for data as usual and
 * find the end at once when no program has the pipe open for writing.
 * Returns the descriptor (close-on-exec), or -1 with errno set. */
int pd_file_open_read(const char *path);

/* The same as a stdio stream read in binary mode, or NULL with errno set. */
FILE *pd_file_fopen_read(const char *path);

/* After nread bytes were read in all from fd: PD_ERR_IO, with one message
 * for every reader, when fd is a named pipe that gave nothing (no program
 * was writing to it); PD_OK otherwise. */
pd_status pd_file_check_fifo(int fd, size_t nread, const char *path, pd_diag *diag);

#endif
