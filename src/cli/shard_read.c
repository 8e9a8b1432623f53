/* shard_read.c: one shard file read and checked line by line (its
 * identity lines, header and pose rows), for posedrop merge. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/file_read.h"
#include "cli/args.h"
#include "cli/shard_read.h"

int shard_fail(const char *file, int line, const char *what)
{
    if (line > 0)
        fprintf(stderr, "%s: %s:%d: %s\n", prog, file, line, what);
    else
        fprintf(stderr, "%s: %s: %s\n", prog, file, what);
    return 0;
}

/* A shard is text of modest lines (a pose row with its chain's counts is
 * about 21 bytes a pose): a NUL byte (binary data, /dev/zero), a line longer
 * than SHARD_LINE_MAX or more pose rows than SHARD_ROWS_MAX end the reading
 * with a message saying what the file looks like, where an endless input
 * would otherwise grow a buffer until the kernel kills the process. */
enum { SHARD_LINE_MAX = 1 << 24, SHARD_ROWS_MAX = 100000 };
typedef enum { LINE_OK, LINE_END, LINE_NUL, LINE_LONG, LINE_NOMEM } line_result;

/* The next line into *out (the caller's), without its end (LF or CR LF). */
static line_result read_line(FILE *f, char **out)
{
    size_t cap = 256, n = 0;
    char *buf = malloc(cap);
    int c;
    line_result r = LINE_OK;
    *out = NULL;
    while (buf && (c = fgetc(f)) != EOF && c != '\n') {
        if (c == '\0' || n == SHARD_LINE_MAX) {
            r = c == '\0' ? LINE_NUL : LINE_LONG;
            break;
        }
        if (n + 1 >= cap) {
            char *b = realloc(buf, cap *= 2);
            if (!b) {
                r = LINE_NOMEM;
                break;
            }
            buf = b;
        }
        buf[n++] = (char)c;
    }
    if (!buf)
        return LINE_NOMEM;
    if (r != LINE_OK) {
        free(buf);
        return r;
    }
    if (n == 0 && feof(f)) {
        free(buf);
        return LINE_END;
    }
    /* A shard copied through a Windows machine ends its lines in CR LF. */
    if (n > 0 && buf[n - 1] == '\r')
        n--;
    buf[n] = '\0';
    *out = buf;
    return LINE_OK;
}

/* The message of a line that could not be read; 0. */
static int line_fail(const char *file, int line, line_result r)
{
    char msg[200];
    if (r == LINE_NOMEM)
        return shard_fail(file, 0, "out of memory");
    snprintf(msg, sizeof msg, "not a shard: %s (a shard is the text 'posedrop --shard K/N' "
             "prints)", r == LINE_NUL ? "a NUL byte, as in binary data"
                                      : "a line longer than 16777216 bytes");
    return shard_fail(file, line, msg);
}

static int parse_count(const char *s, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s, &end, 10);
    if (end == s || (*end != '\0' && *end != ',') || errno || v < 0)
        return 0;
    *out = v;
    return 1;
}

/* The value of key=... in a line of words, copied into buf; NULL if absent. */
const char *shard_find_word(const char *line, const char *key, char *buf, size_t size)
{
    size_t kl = strlen(key);
    for (const char *p = line; (p = strstr(p, key)) != NULL; p += kl) {
        if ((p != line && p[-1] != ' ') || p[kl] != '=')
            continue;
        const char *v = p + kl + 1;
        size_t len = strcspn(v, " ");
        if (len >= size)
            return NULL;
        memcpy(buf, v, len);
        buf[len] = '\0';
        return buf;
    }
    return NULL;
}

/* Column index of name in a CSV header, -1 if absent. */
static int column(const char *header, const char *name)
{
    size_t nl = strlen(name);
    int col = 0;
    for (const char *p = header;; col++) {
        size_t len = strcspn(p, ",");
        if (len == nl && strncmp(p, name, nl) == 0)
            return col;
        if (!p[len])
            return -1;
        p += len + 1;
    }
}

/* The field of a CSV row at column col. */
static const char *field(const char *row, int col)
{
    for (int c = 0; c < col; c++) {
        row = strchr(row, ',');
        if (!row)
            return "";
        row++;
    }
    return row;
}

static int read_rows(FILE *f, shard_file *s, const char *header, int *lineno)
{
    int cpose = column(header, "pose"), cn = column(header, "n"), ccount = column(header, "count"),
        cuns = column(header, "unsettled"), cpart = column(header, "partial"),
        cfirst = column(header, "first");
    if (cpose < 0 || cn < 0 || ccount < 0 || cuns < 0 || cpart < 0)
        return shard_fail(s->file, *lineno, "expected a header with the columns pose, n, count, "
                          "unsettled and partial (a shard of a run with -n)");
    char **rows = NULL, *line;
    int nrows = 0, cap = 0, ok = 1;
    line_result lr;
    while (ok && (lr = read_line(f, &line)) == LINE_OK) {
        if (nrows == SHARD_ROWS_MAX) {
            free(line);
            ok = shard_fail(s->file, *lineno + nrows + 1, "not a shard: more than 100000 pose "
                            "rows");
            break;
        }
        if (nrows == cap) {
            char **r = realloc(rows, sizeof *r * (size_t)(cap = 2 * cap + 64));
            if (!r) {
                free(line);
                ok = shard_fail(s->file, 0, "out of memory");
                break;
            }
            rows = r;
        }
        rows[nrows++] = line;
    }
    if (ok && lr != LINE_END)
        ok = line_fail(s->file, *lineno + nrows + 1, lr);
    ok = ok && (nrows > 0 || shard_fail(s->file, *lineno, "no pose rows after the header"));
    s->nposes = nrows;
    size_t k = (size_t)(nrows > 0 ? nrows : 1);
    s->count = calloc(k, sizeof *s->count);
    if (cfirst >= 0) {
        s->first = calloc(k, sizeof *s->first);
        s->to = calloc(k * k, sizeof *s->to);
    }
    if (!s->count || (cfirst >= 0 && (!s->first || !s->to)))
        ok = shard_fail(s->file, 0, "out of memory");
    char msg[160];
    for (int i = 0; ok && i < nrows; i++) {
        int ln = *lineno + 1 + i;
        long pose = 0, n = 0, uns = 0, part = 0;
        ok = parse_count(field(rows[i], cpose), &pose) && pose == i + 1 &&
             parse_count(field(rows[i], cn), &n) && parse_count(field(rows[i], ccount), &s->count[i]) &&
             parse_count(field(rows[i], cuns), &uns) && parse_count(field(rows[i], cpart), &part) &&
             part <= 1 && (i == 0 || (n == s->drops && uns == s->unsettled && part == s->partial));
        for (int j = -1; ok && cfirst >= 0 && j < nrows; j++)
            ok = parse_count(field(rows[i], cfirst + 1 + j),
                             j < 0 ? &s->first[i] : &s->to[(size_t)i * k + (size_t)j]);
        if (!ok) {
            snprintf(msg, sizeof msg, "expected pose %d's row: non-negative counts%s, n, "
                     "unsettled and partial as in the first row", i + 1,
                     cfirst >= 0 ? " (count, first, to_1 ..)" : "");
            shard_fail(s->file, ln, msg);
        }
        s->drops = n;
        s->unsettled = uns;
        s->partial = (int)part;
    }
    for (int i = 0; i < nrows; i++)
        free(rows[i]);
    free(rows);
    *lineno += nrows;
    return ok;
}

/* Reads one shard file into s; 0 (with a message) if it is not one. */
int shard_read(const char *file, shard_file *s)
{
    memset(s, 0, sizeof *s);
    s->file = file;
    FILE *f = pd_file_fopen_read(file);
    if (!f) {
        fprintf(stderr, "%s: %s: cannot read: %s\n", prog, file, strerror(errno));
        return 0;
    }
    char *lines[3] = {NULL, NULL, NULL};
    int got = 0;
    line_result lr = LINE_OK;
    while (got < 3 && (lr = read_line(f, &lines[got])) == LINE_OK)
        got++;
    char *l1 = lines[0], *l2 = lines[1], *hdr = lines[2];
    pd_diag pipe;
    pd_diag_init(&pipe);
    if (!l1 && lr == LINE_END && pd_file_check_fifo(fileno(f), 0, file, &pipe) != PD_OK) {
        fprintf(stderr, "%s: %s\n", prog, pipe.message);
        fclose(f);
        return 0;
    }
    char version[64], buf[64];
    int ok = 1, lineno = 3;
    if (got < 3 && lr != LINE_OK && lr != LINE_END)
        ok = line_fail(file, got + 1, lr);
    else if (!l1 || strncmp(l1, "# posedrop ", 11) != 0 ||
             sscanf(l1 + 11, "%63s", version) != 1 ||
             !shard_find_word(l1, "shard", buf, sizeof buf) ||
             sscanf(buf, "%d/%d", &s->k, &s->n) != 2 || s->n < 1 || s->k < 1 || s->k > s->n)
        ok = shard_fail(file, 1, "not a shard: expected a first line '# posedrop VERSION "
                        "shard=K/N ...', as 'posedrop --shard K/N' prints");
    if (ok && (!l2 || strncmp(l2, "# totals ", 9) != 0 ||
               !shard_find_word(l2, "collisions", buf, sizeof buf) ||
               !parse_count(buf, &s->collisions) ||
               !shard_find_word(l2, "energy_gain", buf, sizeof buf) ||
               !parse_count(buf, &s->energy_gain) ||
               !shard_find_word(l2, "fallbacks", buf, sizeof buf) ||
               !parse_count(buf, &s->fallbacks)))
        ok = shard_fail(file, 2, "expected '# totals collisions=C energy_gain=G fallbacks=F'");
    if (ok && !hdr)
        ok = shard_fail(file, 3, "expected the CSV header");
    if (ok)
        ok = read_rows(f, s, hdr, &lineno);
    if (ok && s->partial) {
        snprintf(buf, sizeof buf, "shard %d/%d was interrupted (partial)", s->k, s->n);
        ok = shard_fail(file, 0, buf);
        fprintf(stderr, "%s: run it again to the end before merging\n", prog);
    }
    if (ok) {
        /* The identity after shard=K/N, to compare with the other shards'. */
        s->identity = strdup(strstr(l1, " shard=") + 7 + strcspn(strstr(l1, " shard=") + 7, " "));
        s->version = strdup(version);
        ok = s->identity && s->version;
    }
    free(l1);
    free(l2);
    free(hdr);
    fclose(f);
    return ok;
}

void shard_file_clear(shard_file *s)
{
    free(s->identity);
    free(s->version);
    free(s->count);
    free(s->first);
    free(s->to);
    memset(s, 0, sizeof *s);
}
