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

/* A part dropped onto a feeder, a belt or a bin: from a grain of 0.5 mm (a
 * small SMD part, a watch screw) to 2 m across (a panel). A file in
 * millimetres read as metres is a thousand times too large, one in metres
 * read as millimetres a thousand times too small, so either lands well
 * outside this range for any part inside it. */
#define PLAUSIBLE_SIZE_MIN 0.5e-3 /* m, bounding-box diagonal */
#define PLAUSIBLE_SIZE_MAX 2.0    /* m */

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

/* From the smallest unit to the largest. A part too large is suggested the
 * first smaller unit that makes it plausible (millimetres, the usual CAD
 * unit, first); one too small the first larger one from the other end
 * (metres first). */
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

static int plausible_size(double size)
{
    return size >= PLAUSIBLE_SIZE_MIN && size <= PLAUSIBLE_SIZE_MAX;
}

/* "54 m", "0.04 mm": a length in metres, or in millimetres under 1 m. */
static void length_text(double m, char *buf, size_t size)
{
    if (m >= 1.0)
        snprintf(buf, size, "%.3g m", m);
    else
        snprintf(buf, size, "%.3g mm", m * 1e3);
}

static const char *option_of(pd_units units)
{
    for (int k = 0; k < NUNITS; k++)
        if (unit_names[k].units == units)
            return unit_names[k].option;
    return "?";
}

/* Returns 1 when it warned. */
static int warn_size(const cli_args *a, double size)
{
    if (plausible_size(size))
        return 0;
    char len[32];
    length_text(size, len, sizeof len);
    fprintf(stderr, "%s: warning: %s: the part is %s across", prog, a->path, len);
    double file_size = size / pd_units_scale(a->read.units); /* in the file's numbers */
    int large = size > PLAUSIBLE_SIZE_MAX;
    for (int i = 0; i < NUNITS; i++) {
        int k = large ? i : NUNITS - 1 - i;
        if (unit_names[k].units == a->read.units ||
            !plausible_size(file_size * pd_units_scale(unit_names[k].units)))
            continue;
        if (a->read.units == PD_UNITS_M)
            fprintf(stderr, "; if the file is in %s, add --units %s\n", unit_names[k].name,
                    unit_names[k].option);
        else
            fprintf(stderr, "; if the file is in %s, give --units %s, not --units %s\n",
                    unit_names[k].name, unit_names[k].option, option_of(a->read.units));
        return 1;
    }
    fprintf(stderr, "; is that what you meant? (--units says what the file's numbers mean)\n");
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
    if (!warn_size(a, part->size) && a->dynamic)
        warn_height(a, part->size);
    if (a->dynamic)
        warn_tumble(a, part->size);
}
