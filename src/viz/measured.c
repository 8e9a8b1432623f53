/* measured.c: reading a measured pose distribution (--measured). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/file_read.h"
#include "base/stats.h"
#include "base/text.h"
#include "viz/viz.h"
#include "viz/viz_const.h"

/* A file of at most this many poses: more is not a pose table. */
enum { MAX_POSES = 100000, LINE_MAX_LEN = 4096 };

void viz_measured_free(viz_measured *m)
{
    if (!m)
        return;
    free(m->p);
    free(m->lo);
    free(m->hi);
    free(m->path);
    free(m);
}

/* Splits line (modified) at commas into at most max fields; trims blanks and
 * a trailing carriage return. Returns the count. */
static int split(char *line, char **field, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        char *comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        while (*p == ' ' || *p == '\t')
            p++;
        char *end = p + strlen(p);
        while (end > p && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r' || end[-1] == '\n'))
            *--end = '\0';
        if (n < max)
            field[n] = p;
        n++;
        if (!comma)
            return n;
        p = comma + 1;
    }
}

static int number(const char *s, double *out)
{
    return pd_parse_double(s, strlen(s), out) == PD_NUM_OK;
}

/* Half a unit in the last digit the text of a number gives (0.333: 5e-4,
 * 1.5e-2: 5e-4), the most by which it may differ from what it was rounded
 * from. */
static double half_last_digit(const char *s)
{
    const char *dot = strchr(s, '.'), *e = strpbrk(s, "eE");
    int decimals = 0;
    for (const char *c = dot ? dot + 1 : s + strlen(s); *c >= '0' && *c <= '9'; c++)
        decimals++;
    long exponent = e ? strtol(e + 1, NULL, 10) : 0;
    return 0.5 * pow(10.0, (double)(exponent - decimals));
}

/* One line into line (size bytes): 1, 0 at the end of the file, -1 for a
 * line too long, -2 for a NUL byte (no text file holds one). */
static int read_line(FILE *f, char *line, int size)
{
    int n = 0, c;
    while ((c = getc(f)) != EOF) {
        if (c == '\0')
            return -2;
        if (n == size - 1)
            return -1;
        line[n++] = (char)c;
        if (c == '\n')
            break;
    }
    line[n] = '\0';
    return n > 0 ? 1 : 0;
}

typedef struct {
    int pose;
    double value;
} row;

pd_status viz_measured_read(const char *path, viz_measured **out, pd_diag *diag)
{
    FILE *f = pd_file_fopen_read(path);
    if (!f)
        return pd_fail(diag, PD_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    char line[LINE_MAX_LEN];
    char *field[64];
    int col_pose = -1, col_count = -1, col_p = -1, col_n = -1, ncols = 0;
    long lineno = 0;
    double n_given = -1.0;
    row *rows = NULL;
    int nrows = 0, cap = 0, maxpose = 0;
    pd_status st = PD_OK;
    int got;
    while (st == PD_OK && (got = read_line(f, line, sizeof line)) != 0) {
        lineno++;
        if (got < 0) {
            st = got == -2 ? pd_fail(diag, PD_ERR_PARSE, "%s:%ld: a NUL byte: binary data, not a "
                                     "CSV table", path, lineno)
                           : pd_fail(diag, PD_ERR_PARSE, "%s:%ld: line longer than %d "
                                     "characters", path, lineno, LINE_MAX_LEN - 2);
            break;
        }
        char *p = line;
        /* A UTF-8 byte order mark, as spreadsheets write one, is no text. */
        if (lineno == 1 && strncmp(p, "\xEF\xBB\xBF", 3) == 0)
            memmove(p, p + 3, strlen(p + 3) + 1);
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0' || *p == '\n' || *p == '\r' || *p == '#')
            continue;
        int nf = split(line, field, 64);
        if (ncols == 0) {
            ncols = nf;
            for (int i = 0; i < nf && i < 64; i++) {
                if (!strcmp(field[i], "pose")) col_pose = i;
                else if (!strcmp(field[i], "count")) col_count = i;
                else if (!strcmp(field[i], "p")) col_p = i;
                else if (!strcmp(field[i], "n")) col_n = i;
            }
            if (col_pose < 0 || (col_count < 0) == (col_p < 0) || (col_n >= 0 && col_p < 0))
                st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected a header with the columns "
                             "pose and count, or pose and p (and optionally n)", path, lineno);
            continue;
        }
        if (nf != ncols) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected %d fields as in the header, found %d",
                         path, lineno, ncols, nf);
            break;
        }
        double pose, v = 0.0, nv = 0.0;
        const char *vtext = field[col_count >= 0 ? col_count : col_p];
        if (!number(field[col_pose], &pose) || pose != floor(pose) || pose < 1 || pose > MAX_POSES) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected a pose number from 1 to %d, got '%s'",
                         path, lineno, MAX_POSES, field[col_pose]);
            break;
        }
        if (col_count >= 0 && (!number(vtext, &v) || v != floor(v) || v < 0 || v > 1e15)) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected a count (a whole number >= 0), got '%s'",
                         path, lineno, vtext);
            break;
        }
        if (col_p >= 0 && (!number(vtext, &v) || v < 0.0 || v > 1.0)) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected a probability from 0 to 1, got '%s'",
                         path, lineno, vtext);
            break;
        }
        if (col_n >= 0) {
            if (!number(field[col_n], &nv) || nv != floor(nv) || nv < 1 || nv > 1e15 ||
                (n_given >= 0 && nv != n_given)) {
                st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected n, the same whole number of "
                             "observations on every row, got '%s'", path, lineno, field[col_n]);
                break;
            }
            n_given = nv;
            /* p of n drops is a whole number of drops, to p's last digit:
             * 0.333 of 10 is no count, and would be rounded silently. */
            double drops = v * nv;
            if (fabs(drops - nearbyint(drops)) > nv * half_last_digit(vtext) + 1e-9 * nv) {
                st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: p %s of n %s drops is %.6g drops, not a "
                             "whole number: give p to enough digits, or the counts (pose,count)",
                             path, lineno, vtext, field[col_n], drops);
                break;
            }
        }
        for (int i = 0; i < nrows; i++)
            if (rows[i].pose == (int)pose) {
                st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: pose %d given twice", path, lineno,
                             (int)pose);
                break;
            }
        if (st != PD_OK)
            break;
        if (nrows == cap) {
            cap = cap ? 2 * cap : 16;
            row *r = realloc(rows, (size_t)cap * sizeof *r);
            if (!r) {
                st = pd_fail(diag, PD_ERR_NOMEM, "out of memory");
                break;
            }
            rows = r;
        }
        rows[nrows].pose = (int)pose;
        rows[nrows].value = v;
        nrows++;
        if ((int)pose > maxpose)
            maxpose = (int)pose;
    }
    if (st == PD_OK && ferror(f))
        st = pd_fail(diag, PD_ERR_IO, "%s: read error", path);
    if (st == PD_OK && lineno == 0)
        st = pd_file_check_fifo(fileno(f), 0, path, diag);
    fclose(f);
    double total = 0.0;
    for (int i = 0; i < nrows; i++)
        total += rows[i].value;
    if (st == PD_OK && nrows == 0)
        st = pd_fail(diag, PD_ERR_PARSE, "%s: no %s", path,
                     ncols ? "rows after the header" : "header (pose,count or pose,p)");
    else if (st == PD_OK && col_count >= 0 && !(total > 0))
        st = pd_fail(diag, PD_ERR_RANGE, "%s: the counts add up to 0", path);
    else if (st == PD_OK && col_count >= 0 && total > 1e15)
        st = pd_fail(diag, PD_ERR_RANGE, "%s: the counts add up to %.6g, more than the 1e15 "
                     "drops a count may be", path, total);
    else if (st == PD_OK && col_p >= 0 && fabs(total - 1.0) > VIZ_MEASURED_SUM_TOL)
        st = pd_fail(diag, PD_ERR_RANGE, "%s: the p column adds up to %.6g, expected 1 (within %g)",
                     path, total, VIZ_MEASURED_SUM_TOL);
    viz_measured *m = NULL;
    if (st == PD_OK) {
        m = calloc(1, sizeof *m);
        int ci = col_count >= 0 || col_n >= 0;
        if (m) {
            m->p = calloc((size_t)maxpose, sizeof *m->p);
            m->lo = ci ? calloc((size_t)maxpose, sizeof *m->lo) : NULL;
            m->hi = ci ? calloc((size_t)maxpose, sizeof *m->hi) : NULL;
            m->path = malloc(strlen(path) + 1);
        }
        if (!m || !m->p || !m->path || (ci && (!m->lo || !m->hi))) {
            viz_measured_free(m);
            m = NULL;
            st = pd_fail(diag, PD_ERR_NOMEM, "out of memory");
        }
    }
    if (st == PD_OK) {
        strcpy(m->path, path);
        m->npose = maxpose;
        m->n = col_count >= 0 ? (long)total : col_n >= 0 ? (long)n_given : 0;
        for (int i = 0; i < nrows; i++) {
            int k = rows[i].pose - 1;
            m->p[k] = col_count >= 0 ? rows[i].value / total : rows[i].value;
        }
        if (m->lo)
            for (int k = 0; k < maxpose; k++)
                pd_wilson(lround(m->p[k] * (double)m->n), m->n, PD_Z95, &m->lo[k],
                          &m->hi[k]);
        *out = m;
    }
    free(rows);
    return st;
}
