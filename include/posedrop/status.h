/* posedrop/status.h: the one status enum every library call returns.
 *
 * 0 is success; every failure has its own name so a caller can tell bad input
 * (the user's to fix) from a failed internal check (ours to fix). No library
 * call aborts or exits. A call that fails leaves its outputs untouched and, when
 * given a pd_diag, writes a one-line message saying what went wrong and where. */
#ifndef POSEDROP_STATUS_H
#define POSEDROP_STATUS_H

#include "posedrop/export.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum pd_status {
    PD_OK = 0,
    PD_ERR_USAGE,          /* invalid argument to a library call (NULL, out of range) */
    PD_ERR_IO,             /* a file could not be opened or read */
    PD_ERR_FORMAT,         /* unknown or unrecognisable file format */
    PD_ERR_PARSE,          /* malformed content: bad token, wrong count, truncated file */
    PD_ERR_NONFINITE,      /* a NaN or infinite number in the input */
    PD_ERR_RANGE,          /* an index out of range, a count too large to be real, or a
                              part size outside the supported range (docs/limits.md) */
    PD_ERR_TOO_FEW_POINTS, /* fewer than 4 distinct points */
    PD_ERR_COLOCATED,      /* all points coincide within the weld tolerance */
    PD_ERR_COLLINEAR,      /* all points on one line */
    PD_ERR_COPLANAR,       /* all points on one plane: the part has no volume */
    PD_ERR_NOT_CLOSED,     /* the mesh has boundary or non-manifold edges */
    PD_ERR_ORIENTATION,    /* faces cannot be oriented consistently (non-orientable), or
                              oriented they bound no solid: the surface passes through
                              itself or shells overlap (impossible mass properties) */
    PD_ERR_COM_OUTSIDE,    /* centre of mass outside the hull or on its boundary */
    PD_ERR_NO_CONVERGENCE, /* an iteration did not finish within its bound */
    PD_ERR_NOMEM,          /* memory allocation failed */
    PD_ERR_INTERNAL,       /* an internal consistency check failed: a bug */
    PD_ERR_UNAVAILABLE,    /* asked for something this program was not linked with
                              (the Bullet engine without libposedrop-bullet) */
    PD_ERR_CANCELLED,      /* stopped by the caller's cancel flag before it had a
                              result (pd_fit_run; pd_sim_run instead returns PD_OK
                              with the drops done, marked partial) */
    PD_STATUS_COUNT
} pd_status;

/* Short fixed English name of a status, e.g. "parse error". Never NULL. */
PD_API const char *pd_status_str(pd_status status);

/* 1 if the status blames the input (file or arguments), 0 if it is internal.
 * The CLI maps the first kind to exit code 2 and the second to exit code 1. */
PD_API int pd_status_is_input_error(pd_status status);

#ifdef __cplusplus
}
#endif
#endif
