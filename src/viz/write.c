/* write.c: each wanted figure into its file (viz_write). */
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

static pd_status save(const char *path, const vbuf *b, pd_diag *diag)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
    int ok = fwrite(b->data, 1, b->len, f) == b->len;
    ok &= fflush(f) == 0 && !ferror(f);
    ok &= fclose(f) == 0;
    return ok ? PD_OK : pd_fail(diag, PD_ERR_IO, "%s: write error", path);
}

typedef pd_status (*figure_fn)(const viz_input *, int, vbuf *, pd_diag *);

static pd_status one(const char *path, figure_fn fn, const viz_input *in, pd_diag *diag)
{
    if (!path)
        return PD_OK;
    vbuf b;
    vbuf_init(&b);
    pd_status st = fn(in, 1, &b, diag);
    if (st == PD_OK)
        st = save(path, &b, diag);
    vbuf_free(&b);
    return st;
}

pd_status viz_write(const viz_files *files, const viz_input *in, const viz_run *run,
                    pd_diag *diag)
{
    pd_status st = one(files->svg, viz_gallery, in, diag);
    if (st == PD_OK)
        st = one(files->chart, viz_chart, in, diag);
    if (st == PD_OK)
        st = one(files->sphere, viz_sphere, in, diag);
    if (st == PD_OK && files->report) {
        vbuf b;
        vbuf_init(&b);
        st = viz_report(in, run, &b, diag);
        if (st == PD_OK)
            st = save(files->report, &b, diag);
        vbuf_free(&b);
    }
    return st;
}
