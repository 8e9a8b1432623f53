/* posedrop/version.h: the version of the API, the one place it is written.
 *
 * The Makefile reads the three numbers from here for the shared library's
 * file name and soname (libposedrop.so.MAJOR), posedrop.pc and the CLI's
 * --version. The macros give the version a program was compiled against,
 * pd_version() that of the library it runs with. */
#ifndef POSEDROP_VERSION_H
#define POSEDROP_VERSION_H

#include "posedrop/export.h"

#define PD_VERSION_MAJOR 0
#define PD_VERSION_MINOR 1
#define PD_VERSION_PATCH 0

#define PD_VERSION_TEXT_(x) #x
#define PD_VERSION_TEXT(x) PD_VERSION_TEXT_(x)
/* "MAJOR.MINOR.PATCH" */
#define PD_VERSION_STRING                                                                  \
    PD_VERSION_TEXT(PD_VERSION_MAJOR) "." PD_VERSION_TEXT(PD_VERSION_MINOR) "."            \
    PD_VERSION_TEXT(PD_VERSION_PATCH)
/* One number that grows with every release: MAJOR * 10000 + MINOR * 100 + PATCH. */
#define PD_VERSION_NUMBER (PD_VERSION_MAJOR * 10000 + PD_VERSION_MINOR * 100 + PD_VERSION_PATCH)

#ifdef __cplusplus
extern "C" {
#endif

/* The running library's version, "MAJOR.MINOR.PATCH" (PD_VERSION_STRING when
 * it was built). A program compiled against one version may check it runs
 * with a compatible one: same MAJOR, MINOR at least its own. Never NULL. */
PD_API const char *pd_version(void);

#ifdef __cplusplus
}
#endif
#endif
