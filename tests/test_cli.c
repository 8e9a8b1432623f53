#include "check.h"
#include "suites.h"

void suite_cli(void)
{
}
