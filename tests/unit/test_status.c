/* test_status.c: status names and their classification. */
#include <string.h>
#include "check.h"
#include "posedrop/status.h"
#include "posedrop/diag.h"
#include "base/fail.h"
#include "suites.h"

static int nseen;
static char last[PD_DIAG_MESSAGE_LEN];
static void collect(void *user, const char *msg)
{
    (void)user;
    nseen++;
    strcpy(last, msg);
}

void suite_status(void)
{
    /* Every status has its own name; none is shared or missing. */
    for (int s = 0; s < PD_STATUS_COUNT; s++) {
        CHECK(pd_status_str((pd_status)s) != NULL);
        CHECK(strcmp(pd_status_str((pd_status)s), "unknown status") != 0);
        for (int t = 0; t < s; t++)
            CHECK(strcmp(pd_status_str((pd_status)s), pd_status_str((pd_status)t)) != 0);
    }
    CHECK(strcmp(pd_status_str((pd_status)PD_STATUS_COUNT), "unknown status") == 0);
    CHECK(strcmp(pd_status_str((pd_status)-1), "unknown status") == 0);

    /* Input errors exit 2, internal ones 1, success is neither. */
    CHECK_INT(pd_status_is_input_error(PD_OK), 0);
    CHECK_INT(pd_status_is_input_error(PD_ERR_PARSE), 1);
    CHECK_INT(pd_status_is_input_error(PD_ERR_COM_OUTSIDE), 1);
    CHECK_INT(pd_status_is_input_error(PD_ERR_INTERNAL), 0);
    CHECK_INT(pd_status_is_input_error(PD_ERR_NOMEM), 0);

    /* pd_fail fills the message and passes the status through; NULL diag is fine. */
    pd_diag d;
    pd_diag_init(&d);
    CHECK_INT(pd_fail(&d, PD_ERR_PARSE, "%s:%d: expected %s", "a.off", 3, "a number"), PD_ERR_PARSE);
    CHECK(strcmp(d.message, "a.off:3: expected a number") == 0);
    CHECK_INT(pd_fail(NULL, PD_ERR_RANGE, "x"), PD_ERR_RANGE);

    /* Warnings are counted with or without a callback. */
    pd_warn(&d, "first %d", 1);
    CHECK_INT(d.nwarnings, 1);
    d.warn = collect;
    pd_warn(&d, "second %d", 2);
    CHECK_INT(d.nwarnings, 2);
    CHECK_INT(nseen, 1);
    CHECK(strcmp(last, "second 2") == 0);
    pd_warn(NULL, "ignored");
}
