/* args.c: what every part of the command shares (cli/args.h). */
#include <math.h>
#include "cli/args.h"

const char *prog = "posedrop";

/* Axis-aligned normals come out with round-off components like 1e-17; print
 * them as 0 (and never as -0) so the CSV is stable and readable. */
double cli_clean(double x)
{
    return fabs(x) < PD_PRINT_ZERO ? 0.0 : x;
}
