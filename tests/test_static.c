#include "check.h"
#include "suites.h"

void suite_static(void)
{
}
