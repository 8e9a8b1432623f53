/* diag.c: diagnostics and status names. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "base/fail.h"

void pd_diag_init(pd_diag *diag)
{
    if (!diag)
        return;
    memset(diag, 0, sizeof *diag);
}

pd_status pd_fail(pd_diag *diag, pd_status status, const char *fmt, ...)
{
    if (diag) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(diag->message, sizeof diag->message, fmt, ap);
        va_end(ap);
    }
    return status;
}

void pd_warn(pd_diag *diag, const char *fmt, ...)
{
    if (!diag)
        return;
    diag->nwarnings++;
    if (!diag->warn)
        return;
    char text[PD_DIAG_MESSAGE_LEN];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    diag->warn(diag->warn_user, text);
}

const char *pd_status_str(pd_status status)
{
    static const char *const names[PD_STATUS_COUNT] = {
        [PD_OK] = "success",
        [PD_ERR_USAGE] = "invalid argument",
        [PD_ERR_IO] = "input/output error",
        [PD_ERR_FORMAT] = "unknown file format",
        [PD_ERR_PARSE] = "parse error",
        [PD_ERR_NONFINITE] = "non-finite number",
        [PD_ERR_RANGE] = "value out of range",
        [PD_ERR_TOO_FEW_POINTS] = "too few points",
        [PD_ERR_COLOCATED] = "all points coincide",
        [PD_ERR_COLLINEAR] = "all points collinear",
        [PD_ERR_COPLANAR] = "all points coplanar",
        [PD_ERR_NOT_CLOSED] = "mesh not closed",
        [PD_ERR_ORIENTATION] = "mesh not orientable",
        [PD_ERR_COM_OUTSIDE] = "centre of mass not inside the hull",
        [PD_ERR_NO_CONVERGENCE] = "no convergence",
        [PD_ERR_NOMEM] = "out of memory",
        [PD_ERR_INTERNAL] = "internal error",
        [PD_ERR_UNAVAILABLE] = "not available in this program",
        [PD_ERR_CANCELLED] = "cancelled",
    };
    if ((unsigned)status >= PD_STATUS_COUNT)
        return "unknown status";
    return names[status];
}

int pd_status_is_input_error(pd_status status)
{
    switch (status) {
    case PD_OK:
    case PD_ERR_NOMEM:
    case PD_ERR_INTERNAL:
    case PD_ERR_NO_CONVERGENCE:
    case PD_ERR_CANCELLED:
        return 0;
    default:
        return (unsigned)status < PD_STATUS_COUNT;
    }
}
