/* posedrop/diag.h: diagnostics from library calls.
 *
 * The library never prints. A failing call writes one line into
 * pd_diag.message ("cap.off:12: expected 3 coordinates, found 2"); warnings
 * (re-oriented faces, knife-edge facets) go to an optional callback, so the CLI
 * can send them to stderr and an embedding tool can log or ignore them. Every
 * call taking a pd_diag accepts NULL. */
#ifndef POSEDROP_DIAG_H
#define POSEDROP_DIAG_H

#include "posedrop/export.h"

#ifdef __cplusplus
extern "C" {
#endif

#define PD_DIAG_MESSAGE_LEN 512

typedef void (*pd_warn_fn)(void *user, const char *message);

typedef struct pd_diag {
    char message[PD_DIAG_MESSAGE_LEN]; /* set by the failing call; "" otherwise */
    pd_warn_fn warn;                   /* may be NULL: warnings are only counted */
    void *warn_user;                   /* passed back to warn */
    int nwarnings;                     /* warnings raised so far */
} pd_diag;

/* Empty message, no callback, zero warnings. Does nothing when diag is NULL. */
PD_API void pd_diag_init(pd_diag *diag);

#ifdef __cplusplus
}
#endif
#endif
