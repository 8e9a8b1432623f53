/* write.c: one picture into an open file (viz_write_file). */
#include <stdio.h>
#include <stdlib.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

pd_status viz_check(const viz_input *in, pd_diag *diag)
{
    viz_entry *e;
    int n;
    pd_status st = viz_entries(in, &e, &n, diag);
    if (st == PD_OK)
        free(e);
    return st;
}

pd_status viz_write_file(viz_kind kind, FILE *f, const viz_input *in, const viz_run *run,
                         pd_diag *diag)
{
    vbuf b;
    vbuf_init(&b);
    pd_status st;
    switch (kind) {
    case VIZ_GALLERY: st = viz_gallery(in, 1, &b, diag); break;
    case VIZ_CHART: st = viz_chart(in, 1, &b, diag); break;
    case VIZ_SPHERE: st = viz_sphere(in, 1, &b, diag); break;
    case VIZ_REPORT: st = viz_report(in, run, &b, diag); break;
    default: st = pd_fail(diag, PD_ERR_USAGE, "no such picture");
    }
    /* Short writes show as ferror(f), which the caller checks on closing. */
    if (st == PD_OK)
        fwrite(b.data, 1, b.len, f);
    vbuf_free(&b);
    return st;
}
