/* version.c: the version the library was built as (posedrop/version.h). */
#include "posedrop/version.h"

const char *pd_version(void)
{
    return PD_VERSION_STRING;
}
