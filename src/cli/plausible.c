/* plausible.c: warnings, on stderr and without --verbose, for a part or a
 * drop height that is possible but unlikely to be what the user meant. The
 * usual cause is a unit: a CAD file in millimetres read as metres (a 40 mm
 * bracket becomes 54 m across and still gives plausible-looking
 * probabilities), or a height in millimetres given to -h, which is in metres
 * whatever --units says. The run goes on: a warning, not a refusal, since
 * the library is right at any scale. */
#include <math.h>
#include <stdio.h>
#include "cli/cli.h"

/* The drop height against the part's size. Drops in practice fall one to a
 * few tens of part sizes (the paper's belt: 0.12 m for parts of 1.5 to 3
 * cm, 4 to 8 sizes). Over 100 sizes the part lands at more than
 * sqrt(200 g L) (4.4 m/s for 1 cm) and bounces for long before it settles:
 * more likely a height in millimetres, or a part in the wrong unit. Under
 * a tenth of its size the part is set down rather than dropped, which
 * hardly turns it: more likely a height in the wrong unit again. A height
 * of 0 says "set down" on purpose and is not warned about. */
#define PLAUSIBLE_HEIGHT_MAX_SIZES 100.0
#define PLAUSIBLE_HEIGHT_MIN_SIZES 0.1

static const struct {
    pd_units units;
    const char *option, *name;
} unit_names[] = {
    {PD_UNITS_MM, "mm", "millimetres"},
    {PD_UNITS_CM, "cm", "centimetres"},
    {PD_UNITS_IN, "in", "inches"},
    {PD_UNITS_M, "m", "metres"},
};
enum { NUNITS = sizeof unit_names / sizeof unit_names[0] };

/* "54 m", "0.04 mm": a length in metres, or in millimetres under 1 m. */
static void length_text(double m, char *buf, size_t size)
{
    if (m >= 1.0)
        snprintf(buf, size, "%.3g m", m);
    else
        snprintf(buf, size, "%.3g mm", m * 1e3);
}

static int unit_index(pd_units units)
{
    for (int k = 0; k < NUNITS; k++)
        if (unit_names[k].units == units)
            return k;
    return NUNITS - 1;
}

int plausible_warn_size(const char *path, double size, pd_units units)
{
    pd_units suggest;
    if (pd_units_plausible(size, units, &suggest))
        return 0;
    char len[32];
    length_text(size, len, sizeof len);
    fprintf(stderr, "%s: warning: %s: the part is %s across", prog, path, len);
    int k = unit_index(suggest);
    if (suggest == units)
        fprintf(stderr, "; is that what you meant? (--units says what the file's numbers mean)\n");
    else if (units == PD_UNITS_M)
        fprintf(stderr, "; if the file is in %s, add --units %s\n", unit_names[k].name,
                unit_names[k].option);
    else
        fprintf(stderr, "; if the file is in %s, give --units %s, not --units %s\n",
                unit_names[k].name, unit_names[k].option, unit_names[unit_index(units)].option);
    return 1;
}

static void warn_height(const cli_args *a, double size)
{
    double h = a->scene.height, ratio = h / size;
    if (h <= 0.0 || (ratio <= PLAUSIBLE_HEIGHT_MAX_SIZES && ratio >= PLAUSIBLE_HEIGHT_MIN_SIZES))
        return;
    char hl[32], sl[32];
    length_text(h, hl, sizeof hl);
    length_text(size, sl, sizeof sl);
    fprintf(stderr, "%s: warning: %s: the drop height, %s, is %.*g times the part's size (%s "
                    "across): %s; -h is in metres, whatever --units says\n", prog, a->path, hl,
            ratio >= 1000.0 ? 6 : 3, ratio >= 1000.0 ? round(ratio) : ratio, sl, ratio > 1.0 ? "more a throw than a drop" : "the part is set down more "
                                                                  "than dropped");
}

/* --tumble against the fall: corners spun far faster than the part lands
 * make each drop a long spin on the floor before it settles (the scene
 * accepts up to 10^4 rad/s, which turns a 1 cm part's corners at 50 m/s
 * where it lands at 1.5 m/s), said before the run rather than left to look
 * like a hang. */
#define PLAUSIBLE_TUMBLE_OVER_FALL 10.0

static void warn_tumble(const cli_args *a, double size)
{
    const pd_dist *t = &a->scene.range[PD_PARAM_TUMBLE];
    double w = t->kind == PD_DIST_FIXED ? a->scene.tumble : t->hi;
    double corner = 0.5 * w * size, fall = sqrt(2.0 * a->scene.gravity * a->scene.height);
    if (corner <= PLAUSIBLE_TUMBLE_OVER_FALL * fmax(fall, sqrt(a->scene.gravity * size)))
        return;
    fprintf(stderr, "%s: warning: %s: --tumble %g rad/s turns the part's corners at %.3g m/s, "
                    "%.0f times the speed it lands at: each drop spins long before it settles, "
                    "and a run may take minutes a drop\n", prog, a->path, w, corner,
            corner / fmax(fall, sqrt(a->scene.gravity * size)));
}

void plausible_warn(const cli_args *a, const pd_part *part)
{
    /* A part of the wrong size makes any height look wrong: one warning, on
     * the likelier cause. */
    if (!plausible_warn_size(a->path, part->size, a->read.units) && a->dynamic)
        warn_height(a, part->size);
    if (a->dynamic)
        warn_tumble(a, part->size);
}
