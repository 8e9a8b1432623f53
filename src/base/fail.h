/* fail.h (private): filling a pd_diag from inside the library. */
#ifndef PD_DIAG_PRIVATE_H
#define PD_DIAG_PRIVATE_H

#include "posedrop/diag.h"
#include "posedrop/status.h"

#if defined(__GNUC__)
#define PD_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define PD_PRINTF(f, a)
#endif

/* Writes the message (printf-style) into diag, if any, and returns status, so
 * a failure reads: return pd_fail(diag, PD_ERR_PARSE, "%s:%d: ...", ...); */
pd_status pd_fail(pd_diag *diag, pd_status status, const char *fmt, ...) PD_PRINTF(3, 4);

/* Counts a warning and passes the formatted text to diag->warn, if set. */
void pd_warn(pd_diag *diag, const char *fmt, ...) PD_PRINTF(2, 3);

#endif
