/* test_input.c: what the mesh reader will take: bytes (an endless input ends
 * at the limit), triangles (a header may not declare more than the limit),
 * and what it says of inputs that are no mesh file at all. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "mesh/mesh_reader.h"
#include "posedrop/mesh.h"
#include "posedrop/sim.h"
#include "posedrop/tolerances.h"
#include "suites.h"
#include "viz/viz.h"

static void expect(pd_status got, pd_status want, const pd_diag *d, const char *mention)
{
    CHECK_STATUS(got, want);
    if (!strstr(d->message, mention))
        printf("     wanted '%s' in: %s\n", mention, d->message);
    CHECK(strstr(d->message, mention) != NULL);
}

/* ASCII STL told from binary by structure, not by its first bytes: a
 * comment line before "solid" or a NUL byte further on used to send it to the
 * binary reader ("declares 544761204 triangles"). */
static void test_stl_kind(void)
{
    static const char tetra[] =
        "solid t\n"
        "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
        "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
        "facet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
        "facet normal 0 0 0\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
        "endsolid t\n";
    char text[1024];
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    /* A comment line first: read as ASCII, by content and by format. */
    snprintf(text, sizeof text, "# exported by a tool\n%s", tetra);
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    for (int forced = 0; forced < 2; forced++) {
        ro.format = forced ? PD_FORMAT_STL : PD_FORMAT_AUTO;
        CHECK_STATUS(pd_mesh_parse(text, strlen(text), "c.stl", &ro, &m, &d), PD_OK);
        CHECK(m && m->ntris == 4 && m->nverts == 4);
        pd_mesh_free(m);
        m = NULL;
    }
    /* A NUL byte on line 5: named, as ASCII STL. */
    size_t n = strlen(tetra);
    memcpy(text, tetra, n);
    char *v = strstr(text, "vertex 0 1 0");
    v[8] = '\0';
    expect(pd_mesh_parse(text, n, "n.stl", NULL, &m, &d), PD_ERR_PARSE, &d,
           "n.stl:5: a NUL byte in ASCII STL");
    /* A binary STL whose header says "solid" is still binary; cut short, it
     * is a truncated binary STL, not bad text. */
    unsigned char bin[84 + 50] = "solid binary header";
    bin[80] = 2;
    ro.format = PD_FORMAT_STL;
    expect(pd_mesh_parse(bin, sizeof bin, "b.stl", &ro, &m, &d), PD_ERR_PARSE, &d,
           "truncated binary STL");
    CHECK(m == NULL);

    /* More than 16 KiB of comment lines before "solid", and a comment line
     * before a byte-order mark: ASCII STL still, by content and by format. */
    size_t cap = 32768 + sizeof tetra, len = 0;
    char *big = malloc(cap);
    CHECK(big != NULL);
    if (!big)
        return;
    while (len < 20000)
        len += (size_t)snprintf(big + len, cap - len, "# a comment line of an exporter, %zu\n", len);
    len += (size_t)snprintf(big + len, cap - len, "%s", tetra);
    char bom[1024];
    int bl = snprintf(bom, sizeof bom, "# exported\n\xEF\xBB\xBF%s", tetra);
    for (int forced = 0; forced < 2; forced++) {
        ro.format = forced ? PD_FORMAT_STL : PD_FORMAT_AUTO;
        CHECK_STATUS(pd_mesh_parse(big, len, "long.stl", &ro, &m, &d), PD_OK);
        CHECK(m && m->ntris == 4);
        pd_mesh_free(m);
        m = NULL;
        CHECK_STATUS(pd_mesh_parse(bom, (size_t)bl, forced ? "bom.stl" : "bom.dat", &ro, &m, &d), PD_OK);
        CHECK(m && m->ntris == 4);
        pd_mesh_free(m);
        m = NULL;
    }
    free(big);
    /* Other text given as STL says it is no STL, binary or ASCII, and what
     * it looks like; never a triangle count made of its bytes. */
    static const char *const other[][2] = {
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "it looks like OBJ"},
        {"# a long comment line, long enough to pass the 84 bytes of a binary STL header\n"
         "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "it looks like OFF"},
        {"hello, world\n", "it looks like text of no mesh format"},
    };
    ro.format = PD_FORMAT_STL;
    for (int i = 0; i < 3; i++) {
        expect(pd_mesh_parse(other[i][0], strlen(other[i][0]), "o.stl", &ro, &m, &d),
               PD_ERR_FORMAT, &d, "does not look like binary STL");
        CHECK(strstr(d.message, other[i][1]) != NULL && strstr(d.message, "declares") == NULL);
        CHECK(m == NULL);
    }
}

/* Bytes this process has read so far (Linux's /proc/self/io), or -1. */
static long long bytes_read(void)
{
    FILE *f = fopen("/proc/self/io", "r");
    long long n = -1;
    if (f) {
        if (fscanf(f, "rchar: %lld", &n) != 1)
            n = -1;
        fclose(f);
    }
    return n;
}

/* A 1 GiB file of NUL bytes (sparse) is refused by its first bytes, the
 * reader's first check, without the rest being read: OFF by its name (the
 * header), OBJ by --format (the first keyword), STL otherwise (the triangle
 * count against the size). */
static void test_head_first(void)
{
    char dir[] = "/tmp/posedrop-head-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    static const char *const names[] = {"zeros.off", "zeros.obj", "zeros.bin"};
    static const char *const said[] = {"zeros.off:1: expected OFF header",
                                       "zeros.obj:1: expected an OBJ keyword",
                                       "zeros.bin: no faces (binary STL with 0 triangles)"};
    for (int i = 0; i < 3; i++) {
        char path[128];
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0600);
        CHECK(fd >= 0 && ftruncate(fd, (off_t)1 << 30) == 0);
        if (fd >= 0)
            close(fd);
        pd_mesh_read_options ro;
        pd_mesh_read_options_default(&ro);
        ro.format = i == 1 ? PD_FORMAT_OBJ : PD_FORMAT_AUTO;
        pd_mesh *m = NULL;
        pd_diag d;
        pd_diag_init(&d);
        long long before = bytes_read();
        pd_status st = pd_mesh_read(path, &ro, &m, &d);
        long long after = bytes_read();
        CHECK(st != PD_OK && m == NULL);
        if (!strstr(d.message, said[i]))
            printf("     wanted '%s' in: %s\n", said[i], d.message);
        CHECK(strstr(d.message, said[i]) != NULL);
        /* The head is 64 KiB; a whole read would be 1 GiB. */
        if (before >= 0 && after >= 0)
            CHECK(after - before < (1 << 20));
        else
            printf("     /proc/self/io unreadable: bytes read not checked\n");
        remove(path);
    }
    remove(dir);
}

/* Reads path as a part (0), a scene file (1) or a measured table (2): 1
 * when refused for input, with a message that names the pipe. */
static int refused_as_fifo(int reader, const char *path)
{
    pd_diag d;
    pd_diag_init(&d);
    pd_status st;
    if (reader == 0) {
        pd_mesh *m = NULL;
        st = pd_mesh_read(path, NULL, &m, &d);
        pd_mesh_free(m);
    } else if (reader == 1) {
        pd_scene sc;
        pd_scene_default(&sc);
        st = pd_scene_read(path, &sc, &d);
    } else {
        viz_measured *m = NULL;
        st = viz_measured_read(path, &m, &d);
        viz_measured_free(m);
    }
    return st == PD_ERR_IO && strstr(d.message, "a named pipe that gave nothing to read") != NULL;
}

/* A named pipe with no writer, as the part, the scene file and the measured
 * table: each refused at once with the same message, where open() used to
 * wait for a writer for ever (the part's reader first, then the others).
 * Run in a child with a watchdog alarm, so that a regression fails (killed
 * by SIGALRM) instead of hanging the suite; the bound is no measure, a
 * fixed run returns at once. */
static void test_fifo(void)
{
    char dir[] = "/tmp/posedrop-fifo-XXXXXX", path[128];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/p.off", dir);
    CHECK(mkfifo(path, 0600) == 0);
    for (int reader = 0; reader < 3; reader++) {
        fflush(stdout);
        pid_t pid = fork();
        if (pid == 0) {
            alarm(120);
            _exit(refused_as_fifo(reader, path) ? 0 : 1);
        }
        int status = 0;
        CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
        CHECK(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    }
    remove(path);
    remove(dir);
}

void suite_input(void)
{
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    /* An endless device ends one byte past the limit, refused as too long. */
    expect(pd_mesh_read_capped("/dev/zero", NULL, 1 << 20, &m, &d), PD_ERR_RANGE, &d,
           "/dev/zero: more than 1048576 bytes");
    CHECK(m == NULL);
    /* A regular file over the limit is refused by its size, unread; at the
     * limit it is read. */
    char path[] = "/tmp/posedrop-input-XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    const char *tetra = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    size_t len = strlen(tetra);
    CHECK(write(fd, tetra, len) == (ssize_t)len);
    close(fd);
    expect(pd_mesh_read_capped(path, NULL, len - 1, &m, &d), PD_ERR_RANGE, &d,
           "posedrop reads mesh files of at most");
    CHECK_STATUS(pd_mesh_read_capped(path, NULL, len, &m, &d), PD_OK);
    CHECK(m && m->ntris == 4);
    pd_mesh_free(m);
    m = NULL;
    remove(path);
    /* A pipe that would go on for ever: the same refusal, in bounded time. */
    FILE *p = popen("exec yes 'v 0 0 0' 2>/dev/null", "r");
    CHECK(p != NULL);
    if (p) {
        char dev[64];
        snprintf(dev, sizeof dev, "/dev/fd/%d", fileno(p));
        pd_mesh_read_options ro;
        pd_mesh_read_options_default(&ro);
        ro.format = PD_FORMAT_OBJ;
        expect(pd_mesh_read_capped(dev, &ro, 1 << 20, &m, &d), PD_ERR_RANGE, &d,
               "more than 1048576 bytes");
        pclose(p);
    }
    /* The real limit is what pd_mesh_read uses. */
    expect(pd_mesh_read("/dev/zero", NULL, &m, &d), PD_ERR_RANGE, &d, "more than 1073741824 bytes");
    /* A directory is named as one. */
    expect(pd_mesh_read("/tmp", NULL, &m, &d), PD_ERR_IO, &d, "/tmp: is a directory");

    /* Triangles: a header may not declare more than PD_MAX_ELEMENTS. */
    char off[128];
    snprintf(off, sizeof off, "OFF\n4 %d 0\n", PD_MAX_ELEMENTS + 1);
    expect(pd_mesh_parse(off, strlen(off), "big.off", NULL, &m, &d), PD_ERR_RANGE, &d,
           "the limit is 67108864");
    unsigned char stl[84] = {0};
    unsigned n = (unsigned)PD_MAX_ELEMENTS + 1;
    stl[80] = (unsigned char)n;
    stl[81] = (unsigned char)(n >> 8);
    stl[82] = (unsigned char)(n >> 16);
    stl[83] = (unsigned char)(n >> 24);
    pd_mesh_read_options ro;
    pd_mesh_read_options_default(&ro);
    ro.format = PD_FORMAT_STL;
    expect(pd_mesh_parse(stl, sizeof stl, "big.stl", &ro, &m, &d), PD_ERR_RANGE, &d,
           "the limit is 67108864");
    CHECK(m == NULL);
    test_stl_kind();
    test_head_first();
    test_fifo();
}
