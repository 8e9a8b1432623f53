/* files.h: reading a whole file in the tests. */
#ifndef PD_TEST_FILES_H
#define PD_TEST_FILES_H

/* The file's bytes, NUL-terminated (caller frees), or NULL if unreadable. */
char *slurp(const char *path);

#endif
