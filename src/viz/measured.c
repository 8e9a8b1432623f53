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
    free(m->set_size);
    free(m->set_pose);
    free(m->set_p);
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
    int pose;      /* 0 for a set */
    int first, nm; /* a set: its poses are members[first .. first + nm) */
    double value;
} row;

/* The pose field: one pose, or with sets a set "3|4" whose poses are
 * appended to *members. Returns 0 (the caller reports) on a bad field. */
static int parse_pose(char *text, int sets, int *pose, int **members, int *nmembers, int *mcap,
                      int *nm)
{
    double v;
    *nm = 0;
    if (!sets || !strchr(text, '|')) {
        if (!number(text, &v) || v != floor(v) || v < 1 || v > MAX_POSES)
            return 0;
        *pose = (int)v;
        return 1;
    }
    *pose = 0;
    for (char *s = text;;) {
        char *bar = strchr(s, '|');
        if (bar)
            *bar = '\0';
        if (!number(s, &v) || v != floor(v) || v < 1 || v > MAX_POSES)
            return 0;
        for (int i = 0; i < *nm; i++)
            if ((*members)[*nmembers - *nm + i] == (int)v)
                return 0;
        if (*nmembers == *mcap) {
            *mcap = *mcap ? 2 * *mcap : 16;
            int *grown = realloc(*members, sizeof *grown * (size_t)*mcap);
            if (!grown)
                return 0;
            *members = grown;
        }
        (*members)[(*nmembers)++] = (int)v;
        (*nm)++;
        if (bar)
            *bar = '|';
        if (!bar)
            break;
        s = bar + 1;
    }
    return *nm >= 2;
}

static pd_status measured_read(const char *path, int sets, viz_measured **out, pd_diag *diag);

pd_status viz_measured_read(const char *path, viz_measured **out, pd_diag *diag)
{
    return measured_read(path, 0, out, diag);
}

pd_status viz_measured_read_sets(const char *path, viz_measured **out, pd_diag *diag)
{
    return measured_read(path, 1, out, diag);
}

static pd_status measured_read(const char *path, int sets, viz_measured **out, pd_diag *diag)
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
    int nrows = 0, cap = 0, maxpose = 0, *members = NULL, nmembers = 0, mcap = 0, nsets = 0;
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
        double v = 0.0, nv = 0.0;
        int pose, nm;
        const char *vtext = field[col_count >= 0 ? col_count : col_p];
        if (!parse_pose(field[col_pose], sets, &pose, &members, &nmembers, &mcap, &nm)) {
            st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: expected a pose number from 1 to %d%s, got "
                         "'%s'", path, lineno, MAX_POSES,
                         sets ? ", or a set of two or more distinct ones as 3|4"
                              : strchr(field[col_pose], '|') ? " (sets of poses as 3|4 are for "
                                                               "posedrop fit)" : "",
                         field[col_pose]);
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
        /* Every pose in one row at most, alone or in a set. */
        const int *mine = nm ? members + nmembers - nm : &pose;
        for (int a = 0; a < (nm ? nm : 1); a++)
            for (int i = 0; st == PD_OK && i < nrows; i++) {
                const int *theirs = rows[i].nm ? members + rows[i].first : &rows[i].pose;
                for (int b = 0; b < (rows[i].nm ? rows[i].nm : 1); b++)
                    if (theirs[b] == mine[a]) {
                        st = pd_fail(diag, PD_ERR_PARSE, "%s:%ld: pose %d given twice", path,
                                     lineno, mine[a]);
                        break;
                    }
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
        rows[nrows].pose = pose;
        rows[nrows].first = nmembers - nm;
        rows[nrows].nm = nm;
        rows[nrows].value = v;
        nrows++;
        nsets += nm > 0;
        for (int a = 0; a < (nm ? nm : 1); a++)
            if (mine[a] > maxpose)
                maxpose = mine[a];
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
            if (nsets) {
                m->set_size = calloc((size_t)nsets, sizeof *m->set_size);
                m->set_pose = calloc((size_t)nmembers, sizeof *m->set_pose);
                m->set_p = calloc((size_t)nsets, sizeof *m->set_p);
            }
        }
        if (!m || !m->p || !m->path || (ci && (!m->lo || !m->hi)) ||
            (nsets && (!m->set_size || !m->set_pose || !m->set_p))) {
            viz_measured_free(m);
            m = NULL;
            st = pd_fail(diag, PD_ERR_NOMEM, "out of memory");
        }
    }
    if (st == PD_OK) {
        strcpy(m->path, path);
        m->npose = maxpose;
        m->n = col_count >= 0 ? (long)total : col_n >= 0 ? (long)n_given : 0;
        int ns = 0, np = 0;
        for (int i = 0; i < nrows; i++) {
            double pv = col_count >= 0 ? rows[i].value / total : rows[i].value;
            if (!rows[i].nm) {
                m->p[rows[i].pose - 1] = pv;
                continue;
            }
            m->set_size[ns] = rows[i].nm;
            m->set_p[ns++] = pv;
            for (int a = 0; a < rows[i].nm; a++)
                m->set_pose[np++] = members[rows[i].first + a];
        }
        m->nsets = ns;
        if (m->lo)
            for (int k = 0; k < maxpose; k++)
                pd_wilson(lround(m->p[k] * (double)m->n), m->n, PD_Z95, &m->lo[k],
                          &m->hi[k]);
        *out = m;
    }
    free(rows);
    free(members);
    return st;
}
