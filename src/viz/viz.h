/* viz.h: posedrop's pictures, written by the program itself (no library):
 * the gallery of stable poses, the chart of the estimates, the gauss-sphere
 * map, and the one-file HTML report holding them. A client of the public
 * API only, kept out of libposedrop (the library never writes files); the
 * command (src/cli) and the tests link it. docs/figures.md shows them. */
#ifndef PD_VIZ_H
#define PD_VIZ_H

#include <stdio.h>
#include "posedrop/posedrop.h"

/* A measured pose distribution (--measured FILE.csv), read before the run. */
typedef struct viz_measured {
    int npose;       /* highest pose number in the file */
    double *p;       /* [npose]: probability of pose i + 1 (0 when absent) */
    double *lo, *hi; /* 95% Wilson interval when counts (or n) were given, else NULL */
    long n;          /* observations (sum of counts, or the n column), 0 if unknown */
    char *path;
    /* Rows whose pose is a set of poses, "3|4" (viz_measured_read_sets
     * only): a label that stands for any of them. */
    int nsets;
    int *set_size;   /* [nsets] poses in each set */
    int *set_pose;   /* the sets' pose numbers, one set after another */
    double *set_p;   /* [nsets] each set's probability, as p */
} viz_measured;

/* Reads a CSV with a header naming the columns pose and count, or pose and
 * p (and optionally n, the observations behind p, for an interval). Errors
 * name the file and line: PD_ERR_IO, PD_ERR_PARSE, PD_ERR_RANGE. */
pd_status viz_measured_read(const char *path, viz_measured **out, pd_diag *diag);
/* The same, where a pose may also be a set of two or more poses, "3|4", each
 * pose counted in one row at most. */
pd_status viz_measured_read_sets(const char *path, viz_measured **out, pd_diag *diag);
void viz_measured_free(viz_measured *m);

/* --crosscheck: the same releases run on the three engines, each one's
 * result per entry (grouped when class_of, like viz_input.sim), in
 * pd_engine_kind's order (impulse, ODE, Bullet); NULL for an engine that did
 * not run (an interrupted run). */
enum { VIZ_ENGINES = 3 };
typedef struct viz_engines {
    const pd_sim_result *sim[VIZ_ENGINES];
} viz_engines;

/* An entry's spread across the engines that ran drops: the lowest and the
 * highest p, and whether the engines disagree beyond their sampling
 * intervals (the lowest 95% upper bound below the highest lower bound: two
 * engines' intervals are apart). ran: how many engines count. */
typedef struct viz_spread {
    double lo, hi;
    int apart, ran;
} viz_spread;
viz_spread viz_engine_spread(const viz_engines *x, int entry);

/* "impulse", "ODE" or "Bullet": engine k's name in words. */
const char *viz_engine_label(int k);

/* What the pictures are made of. One entry per stable pose, or per class of
 * poses with class_of (as --group prints them), in the CSV's order. */
typedef struct viz_input {
    const char *name;             /* the part's name in titles (its file name) */
    const pd_part *part;
    const pd_static_result *res;
    const pd_sim_result *sim;     /* per entry (grouped when class_of), or NULL */
    const int *class_of;          /* res->nposes classes, or NULL */
    int nclasses;
    const char *engine;           /* the dynamic estimator's name for labels */
    const pd_scene *scene;        /* the drops' scene (NULL without drops) */
    const viz_measured *measured; /* or NULL */
    const pd_sensitivity *sensitivity; /* of a run with ranges, or NULL */
    const viz_engines *engines;   /* --crosscheck, or NULL */
} viz_input;

/* What the report says about the run besides the results. */
typedef struct viz_run {
    const char *path;              /* the part's file */
    pd_units units;
    const pd_static_options *estimate;
    const pd_sim_options *sim;
    double seconds_static, seconds_sim, seconds_total;
    int argc;
    char **argv;                   /* the command line, shown so that it can be rerun */
} viz_run;

/* The pictures: --svg, --chart, --sphere, --report. */
typedef enum { VIZ_GALLERY = 0, VIZ_CHART, VIZ_SPHERE, VIZ_REPORT, VIZ_KINDS } viz_kind;

/* Whether in can be drawn: PD_ERR_USAGE when the measured file names a
 * pose the table does not have, so that a run fails before writing. */
pd_status viz_check(const viz_input *in, pd_diag *diag);

/* Writes one picture to f (the caller opens it and catches write errors when
 * it closes it; run is read by the report only). PD_ERR_USAGE when the
 * measured file names a pose the table does not have, PD_ERR_NOMEM. */
pd_status viz_write_file(viz_kind kind, FILE *f, const viz_input *in, const viz_run *run,
                         pd_diag *diag);

#endif
