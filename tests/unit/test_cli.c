/* test_cli.c: the posedrop command as a user runs it: exit codes, CSV on
 * stdout only on success, clear messages on stderr, determinism, and the batch
 * scripts. Runs the built binary (PD_CLI_PATH) from the repository root. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "cli_run.h"
#include "files.h"
#include "suites.h"

typedef struct {
    int nrows;
    double p_qs_sum, p_pqs_sum;
    int ordered, numbered;
} csv_summary;

/* Finds columns by name, as the output contract says tools must. */
static int summarise(const char *csv, csv_summary *s)
{
    memset(s, 0, sizeof *s);
    s->ordered = s->numbered = 1;
    const char *nl = strchr(csv, '\n');
    if (!nl)
        return 0;
    char header[256];
    size_t hl = (size_t)(nl - csv);
    if (hl >= sizeof header)
        return 0;
    memcpy(header, csv, hl);
    header[hl] = '\0';
    int col_pose = -1, col_qs = -1, col_pqs = -1, ncol = 0;
    for (char *tok = strtok(header, ","); tok; tok = strtok(NULL, ","), ncol++) {
        if (strcmp(tok, "pose") == 0)
            col_pose = ncol;
        if (strcmp(tok, "p_qs") == 0)
            col_qs = ncol;
        if (strcmp(tok, "p_pqs") == 0)
            col_pqs = ncol;
    }
    if (col_pose < 0 || col_qs < 0 || col_pqs < 0)
        return 0;
    double prev = 2.0;
    for (const char *p = nl + 1; *p; ) {
        const char *e = strchr(p, '\n');
        if (!e)
            return 0;
        double v[16] = {0};
        int k = 0;
        for (const char *q = p; q < e && k < 16; k++) {
            v[k] = strtod(q, NULL);
            const char *c = memchr(q, ',', (size_t)(e - q));
            q = c ? c + 1 : e;
        }
        if (k != ncol)
            return 0;
        s->nrows++;
        s->numbered &= (int)v[col_pose] == s->nrows;
        s->ordered &= v[col_qs] <= prev * (1 + 1e-6); /* PD_TOL_PROB_TIE_REL */
        prev = v[col_qs];
        s->p_qs_sum += v[col_qs];
        s->p_pqs_sum += v[col_pqs];
        p = e + 1;
    }
    return 1;
}

static void test_usage(void)
{
    char *out, *err;
    CHECK_INT(run("--help", &out, &err), 0);
    CHECK(strstr(out, "usage: posedrop") != NULL);
    CHECK(strstr(out, "--epsilon") != NULL);
    /* The help is generated from the option table: each option listed once
     * (a value counted as an option when getopt takes it). */
    const char *listed[] = {"--units U", "--com X,Y,Z", "-n N", "-j THREADS", "-h H", "-v V",
                            "--seed S", "--scene FILE", "--trials FILE", "--transitions FILE",
                            "--contact-time S", "--initial I", "--version"};
    for (size_t i = 0; i < sizeof listed / sizeof listed[0]; i++) {
        const char *at = strstr(out, listed[i]);
        CHECK(at != NULL && strstr(at + 1, listed[i]) == NULL);
    }
    free(out);
    free(err);
    CHECK_INT(run("--version", &out, &err), 0);
    CHECK(strncmp(out, "posedrop ", 9) == 0);
    free(out);
    free(err);

    expect_failure("", 2, "expected one PART file");
    expect_failure("parts/cap.off parts/cap.off", 2, "exactly one PART");
    /* -h is the drop height, -v the belt velocity; help is --help only. */
    expect_failure("-h parts/cap.off", 2, "-h: height");
    expect_failure("-h -1 -n 10 parts/cap.off", 2, "-h: height");
    expect_failure("-v fast -n 10 parts/cap.off", 2, "-v: belt_speed");
    expect_failure("-n 0 parts/cap.off", 2, "-n");
    expect_failure("-n 12x parts/cap.off", 2, "-n");
    expect_failure("-j 0 -n 10 parts/cap.off", 2, "-j");
    expect_failure("--ci 0.7 parts/cap.off", 2, "--ci");
    expect_failure("--mu -0.1 -n 10 parts/cap.off", 2, "--mu");
    expect_failure("--restitution 2 -n 10 parts/cap.off", 2, "--restitution");
    expect_failure("--restitution-law newton -n 10 parts/cap.off", 2, "--restitution-law");
    expect_failure("--initial sorted -n 10 parts/cap.off", 2, "--initial");
    expect_failure("--contact-time -1e-4 -n 10 parts/cap.off", 2, "--contact-time");
    expect_failure("--contact-time soon -n 10 parts/cap.off", 2, "--contact-time");
    expect_failure("--scene /nonexistent/scene -n 10 parts/cap.off", 2, "/nonexistent/scene");
    expect_failure("--trials /tmp/x.csv parts/cap.off", 2, "--trials");
    expect_failure("--facets -n 10 parts/cap.off", 2, "--facets");
    expect_failure("--frobnicate parts/cap.off", 2, "unknown option '--frobnicate'");
    expect_failure("--units furlong parts/cap.off", 2, "--units");
    expect_failure("--epsilon 91 parts/cap.off", 2, "--epsilon");
    expect_failure("--epsilon nan parts/cap.off", 2, "--epsilon");
    expect_failure("--com 1,2 parts/cap.off", 2, "--com");
    expect_failure("--com 1,2,inf parts/cap.off", 2, "--com");
    expect_failure("--topple sideways parts/cap.off", 2, "--topple");
    expect_failure("parts/cap.off --epsilon", 2, "needs a value");

    /* One reading of numbers for every option (base/number.c): 1e-400 is
     * refused alike, with the range stated; so is every out-of-range value. */
    const char *tiny[] = {"-h 1e-400", "--mu 1e-400", "--vibration 1e-400", "--epsilon 1e-400",
                          "--ci 1e-400", "--dt 1e-400", "--com 1e-400,0,0", "-v 1e-400"};
    for (size_t i = 0; i < sizeof tiny / sizeof tiny[0]; i++) {
        char args[128];
        snprintf(args, sizeof args, "%s parts/cap.off", tiny[i]);
        expect_failure(args, 2, "below the smallest normal double, 2.2e-308");
    }
    expect_failure("-v 1e308 parts/cap.off", 2, "from -1000 to 1000, got '1e308'");
    expect_failure("--seed 9223372036854775808 parts/cap.off", 2,
                   "from 0 to 9223372036854775807, got '9223372036854775808'");
    expect_failure("--epsilon 91 parts/cap.off", 2, "from 0 to 90, got '91'");
    expect_failure("--ci 0.5 -n 10 parts/cap.off", 2, "above 0 and below 0.5");
    expect_failure("-n 1e3 parts/cap.off", 2, "-n: expected a number of drops from 1 to 1000000000");
    /* A blank at either end is accepted alike (the same table either way). */
    char *o1, *e1, *o2, *e2;
    CHECK_INT(run("--epsilon ' 5' parts/cap.off", &o1, &e1), 0);
    CHECK_INT(run("--epsilon '5 ' parts/cap.off", &o2, &e2), 0);
    CHECK(strcmp(o1, o2) == 0 && strlen(o1) > 0);
    free(o1);
    free(e1);
    free(o2);
    free(e2);
    /* The unknown option is named, not the program. */
    expect_failure("-Xn 5 parts/cap.off", 2, "unknown option '-X'");
    expect_failure("--group=1 parts/cap.off", 2, "option '--group' takes no value");
    expect_failure("--re 1 parts/cap.off", 2, "'--re' is the start of more than one option's name");
}

static void test_bad_input(void)
{
    char path[160], args[256];
    expect_failure("/nonexistent/part.off", 2, "/nonexistent/part.off");

    snprintf(path, sizeof path, "%s/bad.off", tmpdir);
    write_file(path, "OFF\n# a comment\n4 4 0\n0 0 0\n1 0 0\n0 x 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n");
    snprintf(args, sizeof args, "%s", path);
    char where[200];
    snprintf(where, sizeof where, "%s:6:", path);
    expect_failure(args, 2, where);

    /* Coplanar points: no volume. */
    snprintf(path, sizeof path, "%s/flat.off", tmpdir);
    write_file(path, "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
    expect_failure(path, 2, "flat.off");

    /* A centre of mass outside the hull is refused. */
    expect_failure("--com 1,0,0 parts/cap.off", 2, "centre of mass");
    expect_failure("--com 0,0,0.014 parts/cap.off", 2, "centre of mass");

    /* An open mesh needs --com. */
    snprintf(path, sizeof path, "%s/open.off", tmpdir);
    write_file(path, "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n");
    expect_failure(path, 2, "--com");
    char *out, *err;
    snprintf(args, sizeof args, "--com 0.2,0.2,0.2 %s", path);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(strstr(err, "warning") != NULL);
    free(out);
    free(err);
}

static void test_results(void)
{
    char *out, *err, *out2, *err2;
    csv_summary s;

    /* Every shipped part runs and gives a consistent table. The sums carry the
     * rounding of 10 printed significant digits: at most 5e-11 per row. */
    const char *parts[] = {"parts/cap.off", "parts/button.off", "--units mm parts/block.stl",
                           "--units mm parts/hexnut.obj"};
    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
        CHECK_INT(run(parts[i], &out, &err), 0);
        CHECK(strncmp(out, "pose,nx,ny,nz,area,height,p_qs,p_pqs\n", 37) == 0);
        CHECK(summarise(out, &s));
        CHECK(s.nrows >= 2);
        CHECK(s.ordered);
        CHECK(s.numbered);
        CHECK_NEAR(s.p_qs_sum, 1.0, 1e-9, "10 printed digits per row");
        CHECK_NEAR(s.p_pqs_sum, 1.0, 1e-9, "10 printed digits per row");
        CHECK(strstr(out, "nan") == NULL && strstr(out, "inf") == NULL);
        free(out);
        free(err);
    }

    /* Every canonical and paper part: closed, oriented, no warning, a table. */
    CHECK_INT(run_cmd("for f in parts/canonical/*.off parts/insulator_cap.off parts/white_button.off "
                      "parts/rect_black_button.off parts/square_black_button.off; do " PD_CLI_PATH
                      " --group \"$f\" > /dev/null || echo \"$f failed\"; done", 1, &out, &err), 0);
    CHECK_INT((int)strlen(out), 0);
    CHECK(strstr(err, "warning") == NULL);
    free(out);
    free(err);

    /* Same input, same bytes. */
    CHECK_INT(run("--topple edge parts/cap.off", &out, &err), 0);
    CHECK_INT(run("--topple edge parts/cap.off", &out2, &err2), 0);
    CHECK(strcmp(out, out2) == 0);
    free(out);
    free(err);
    free(out2);
    free(err2);

    /* Units: the block is 40 x 20 x 10 mm; resting on its largest face the
     * centre is 5 mm up and the face is 8e-4 m^2 (float32 coordinates of
     * integers are exact, so to printed precision). */
    CHECK_INT(run("--units mm parts/block.stl", &out, &err), 0);
    CHECK(strstr(out, "\n1,0,0,-1,0.0008,0.005,") != NULL); /* tie with +z: by normal */
    free(out);
    free(err);

    /* A facet table covers the whole hull. */
    CHECK_INT(run("--facets parts/cap.off", &out, &err), 0);
    CHECK(strncmp(out, "facet,nx,ny,nz,area,height,p_raw,stable,knife,next,rest,pose\n", 61) == 0);
    free(out);
    free(err);

    /* epsilon 0: PQS equals QS column for column. */
    CHECK_INT(run("--epsilon 0 parts/button.off", &out, &err), 0);
    int same = 1;
    for (const char *p = strchr(out, '\n') + 1; *p; p = strchr(p, '\n') + 1) {
        const char *c = p;
        for (int k = 0; k < 6; k++)
            c = strchr(c, ',') + 1;
        double qs = strtod(c, NULL), pqs = strtod(strchr(c, ',') + 1, NULL);
        same &= qs == pqs;
    }
    CHECK(same);
    free(out);
    free(err);
}

static void test_dynamic(void)
{
    char *out, *err, *out2, *err2, args[512], path[160];
    /* The headline command, small: static and dynamic columns together, and
     * the same bytes for one thread or two. */
    CHECK_INT(run("-n 60 -j 1 --units mm parts/block.stl", &out, &err), 0);
    CHECK_INT(run("-n 60 -j 2 --units mm parts/block.stl", &out2, &err2), 0);
    CHECK(strncmp(out, "pose,nx,ny,nz,area,height,p_qs,p_pqs,n,count,p,ci_lo,ci_hi,unsettled,partial\n",
                  77) == 0);
    CHECK(strcmp(out, out2) == 0);
    CHECK(strstr(out, ",60,") != NULL);
    free(out);
    free(err);
    free(out2);
    free(err2);

    /* --trials writes one row per drop; a scene file sets the scene, and
     * options after it override it. */
    snprintf(path, sizeof path, "%s/scene.txt", tmpdir);
    write_file(path, "# a low drop\nheight = 0.01\nmu = 0.5\n");
    char trials[160];
    snprintf(trials, sizeof trials, "%s/trials.csv", tmpdir);
    snprintf(args, sizeof args, "--scene %s --mu 0.2 -n 25 --trials %s --units mm parts/block.stl",
             path, trials);
    CHECK_INT(run(args, &out, &err), 0);
    char *t = slurp(trials);
    int rows = 0;
    for (char *c = t; c && *c; c++)
        rows += *c == '\n';
    CHECK_INT(rows, 26);
    CHECK(t && strncmp(t, "drop,qw,qx,qy,qz,pose,collisions,time,end,partial\n", 50) == 0);
    free(t);
    free(out);
    free(err);

    /* The stepping engines: same columns, same scene; bad choices refused. */
    CHECK_INT(run("-n 40 --engine ode --dt 0.001 --units mm parts/block.stl", &out, &err), 0);
    const char *cols = "pose,nx,ny,nz,area,height,p_qs,p_pqs,n,count,p,";
    CHECK(strncmp(out, cols, strlen(cols)) == 0);
    free(out);
    free(err);
    CHECK_INT(run("-n 40 --engine bullet --dt 0.002 --units mm parts/block.stl", &out, &err), 0);
    CHECK(strstr(out, ",40,") != NULL);
    free(out);
    free(err);
    expect_failure("--engine warp -n 10 parts/cap.off", 2, "--engine");
    expect_failure("--dt 0 -n 10 --engine ode parts/cap.off", 2, "--dt");

    /* The cross-check script: one CSV for the three engines, a verdict per
     * pair, drop-by-drop agreement. */
    char cmd[512];
    CHECK_INT(run_cmd("scripts/crosscheck.sh --help", 1, &out, &err), 0);
    CHECK(strstr(out, "scripts/crosscheck.sh [-n DROPS] [-o DIR]") != NULL && err[0] == '\0');
    free(out);
    free(err);
    /* A flag of posedrop's before a valued option, the part after them. */
    snprintf(cmd, sizeof cmd,
             "scripts/crosscheck.sh -n 12 -o %s/xc -- --group --units mm parts/block.stl", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    CHECK(strstr(out, "impulse vs ode: total variation") != NULL);
    CHECK(strstr(out, "ode vs bullet:") != NULL && strstr(out, "same pose") != NULL);
    free(out);
    free(err);
    snprintf(path, sizeof path, "%s/xc/crosscheck.csv", tmpdir);
    char *x = slurp(path);
    CHECK(x && strncmp(x, "part,pose,engine,n,p,ci_lo,ci_hi,ms_per_drop,unsettled\n", 55) == 0);
    CHECK(x && strstr(x, "\nblock,1,bullet,12,") != NULL);
    free(x);

    /* A bad scene file names its line and prints nothing. */
    write_file(path, "height = 0.01\nfriction = 2\n");
    snprintf(args, sizeof args, "--scene %s -n 5 parts/cap.off", path);
    char where[200];
    snprintf(where, sizeof where, "%s:2:", path);
    expect_failure(args, 2, where);
}

/* Output paths are checked before any work: a bad one fails with exit 2
 * and nothing on stdout even when the part itself would fail later (so the
 * part is never read), a write error at the end (/dev/full) fails with
 * nothing on stdout, and a failed run leaves an existing file as it was. */
static void test_output_paths(void)
{
    char args[512], path[160], dir[160];
    snprintf(dir, sizeof dir, "%s/adir", tmpdir);
    CHECK(mkdir(dir, 0755) == 0);
    const char *bad[][2] = {{"/proc/x", "cannot create a file in /proc"},
                            {"/nonexistent/dir/t.csv", "no such directory /nonexistent/dir"},
                            {dir, "is a directory"}};
    for (int i = 0; i < 3; i++) {
        snprintf(args, sizeof args, "-n 20 --trials %s /nonexistent/part.off", bad[i][0]);
        expect_failure(args, 2, bad[i][1]);
        snprintf(args, sizeof args, "-n 400 --initial stationary --transitions %s "
                 "/nonexistent/part.off", bad[i][0]);
        expect_failure(args, 2, bad[i][1]);
    }
    expect_failure("-n 20 --trials '' /nonexistent/part.off", 2, "an empty file name");
    expect_failure("-n 20 --trials /dev/full parts/cap.off", 1, "/dev/full: write error");
    expect_failure("-n 140 --initial stationary --transitions /dev/full parts/canonical/cube.off",
                   1, "/dev/full: write error");

    /* An existing file survives a failed run whole, and a good run replaces
     * it keeping its permissions, with no temporary left beside it. */
    snprintf(path, sizeof path, "%s/keep.csv", tmpdir);
    write_file(path, "earlier results\n");
    CHECK(chmod(path, 0640) == 0);
    snprintf(args, sizeof args, "-n 5 --trials %s /nonexistent/part.off", path);
    expect_failure(args, 2, "/nonexistent/part.off");
    char *t = slurp(path);
    CHECK(t && strcmp(t, "earlier results\n") == 0);
    free(t);
    char *out, *err;
    snprintf(args, sizeof args, "-n 5 --trials %s parts/cap.off", path);
    CHECK_INT(run(args, &out, &err), 0);
    free(out);
    free(err);
    t = slurp(path);
    CHECK(t && strncmp(t, "drop,qw,", 8) == 0);
    free(t);
    struct stat sb;
    CHECK(stat(path, &sb) == 0 && (sb.st_mode & 0777) == 0640);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "ls -A %s | grep -c posedrop-", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 1); /* grep -c: no line matched */
    CHECK(strncmp(out, "0", 1) == 0);
    free(out);
    free(err);
}

/* A hard (soft 0) or symbolic link to path at name. */
static int link_file_ok(const char *path, const char *name, int soft)
{
    char real[4096];
    if (!soft)
        return link(path, name) == 0;
    return realpath(path, real) && symlink(real, name) == 0;
}

/* A refused run that names path as an output: exit 2, nothing on stdout, a
 * message naming both files, and path as it was, byte for byte (or still
 * absent, when want is NULL). */
static void expect_kept(const char *args, const char *path, const char *want, const char *mention)
{
    expect_failure(args, 2, mention);
    char *now = slurp(path);
    CHECK(want ? now && strcmp(now, want) == 0 : now == NULL);
    free(now);
}

/* An output never overwrites an input, nor another output: the part, a scene
 * or measured file, by the same name, another spelling, a hard or symbolic
 * link; two outputs on one name (existing or not); standard output
 * redirected onto an output. Devices may be named twice. */
static void test_same_file(void)
{
    char part[160], scene[160], measured[160], link[160], name[160], args[1024], cmd[1024];
    char *cube = slurp("parts/canonical/cube.off"), *out, *err;
    snprintf(part, sizeof part, "%s/c.off", tmpdir);
    snprintf(scene, sizeof scene, "%s/s.scene", tmpdir);
    snprintf(measured, sizeof measured, "%s/m.csv", tmpdir);
    CHECK(cube && write_file(part, cube));
    CHECK(write_file(scene, "mu = 0.4\n") && write_file(measured, "pose,count\n1,5\n"));
    const char *opts[] = {"-n 5 --trials", "-n 5 --svg", "--chart", "--sphere", "--report",
                          "-n 140 --initial stationary --transitions"};
    for (int i = 0; i < 6; i++) {
        snprintf(args, sizeof args, "%s %s %s", opts[i], part, part);
        expect_kept(args, part, cube, "is the same file as PART");
    }
    snprintf(args, sizeof args, "-n 5 --scene %s --trials %s %s", scene, scene, part);
    expect_kept(args, scene, "mu = 0.4\n", "--trials");
    snprintf(args, sizeof args, "--measured %s --chart %s %s", measured, measured, part);
    expect_kept(args, measured, "pose,count\n1,5\n", "is the same file as --measured");
    /* Another spelling of the same name, a hard link and a symbolic link. */
    snprintf(args, sizeof args, "--svg %s/../%s/c.off %s", tmpdir, strrchr(tmpdir, '/') + 1, part);
    expect_kept(args, part, cube, "is the same file as PART");
    snprintf(link, sizeof link, "%s/hard.off", tmpdir);
    CHECK(link_file_ok(part, link, 0));
    snprintf(args, sizeof args, "-n 5 --trials %s %s", link, part);
    expect_kept(args, part, cube, "is the same file as PART");
    snprintf(link, sizeof link, "%s/soft.off", tmpdir);
    CHECK(link_file_ok(part, link, 1));
    snprintf(args, sizeof args, "--svg %s %s", link, part);
    expect_kept(args, part, cube, "is the same file as PART");
    /* Two outputs on one name: nothing is written, whether it exists or not. */
    snprintf(name, sizeof name, "%s/x", tmpdir);
    snprintf(args, sizeof args, "-n 5 --trials %s --svg %s %s", name, name, part);
    expect_kept(args, name, NULL, "--trials");
    CHECK(write_file(name, "mine\n"));
    snprintf(args, sizeof args, "--chart %s --report %s/./x %s", name, tmpdir, part);
    expect_kept(args, name, "mine\n", "two outputs may not share a file");
    /* Standard output onto an output. */
    snprintf(cmd, sizeof cmd, "sh -c '" PD_CLI_PATH " -n 5 --trials %s %s >%s'", name, part, name);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 2);
    CHECK(strstr(err, "standard output") != NULL);
    free(out);
    free(err);
    /* A pipe as PART, with its writer there, is read as before. */
    CHECK_INT(run_cmd("sh -c 'cat parts/cap.off | " PD_CLI_PATH " /dev/stdin'", 1, &out, &err), 0);
    CHECK(strncmp(out, "pose,", 5) == 0);
    free(out);
    free(err);
    /* Devices are no files to lose; the part and the options still run. */
    snprintf(args, sizeof args, "--svg /dev/null --chart /dev/null %s", part);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(strncmp(out, "pose,", 5) == 0);
    free(out);
    free(err);
    free(cube);
}

/* Runs posedrop ARGS (words split at spaces) with sig already pending when
 * it starts: the child blocks sig, sends it to itself and execs posedrop,
 * which inherits the blocked mask and the pending signal; it is delivered
 * the moment posedrop unblocks it, however early. Returns the exit status
 * (-1 if killed); *out is what it printed on stdout. */
static int run_signalled(int sig, const char *args, char **out)
{
    char outp[160], words[512], *argv[32];
    int argc = 0;
    snprintf(outp, sizeof outp, "%s/signalled.out", tmpdir);
    snprintf(words, sizeof words, "%s", args);
    argv[argc++] = (char *)PD_CLI_PATH;
    for (char *w = strtok(words, " "); w && argc < 31; w = strtok(NULL, " "))
        argv[argc++] = w;
    argv[argc] = NULL;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        sigset_t set;
        sigemptyset(&set);
        sigaddset(&set, sig);
        if (sigprocmask(SIG_BLOCK, &set, NULL) != 0 || kill(getpid(), sig) != 0 ||
            !freopen(outp, "w", stdout) || !freopen("/dev/null", "w", stderr))
            _exit(126);
        execv(PD_CLI_PATH, argv);
        _exit(127);
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
    *out = slurp(outp);
    if (!*out)
        *out = calloc(1, 1);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* A signal at the very start (before options are parsed or the part read)
 * ends the run with 128 + its number and nothing on stdout, with or without
 * drops; --dt, which only the stepping engines use, is refused with the
 * impulse engine instead of ignored. */
static void test_early_signal(void)
{
    const struct {
        int sig;
        const char *args;
    } runs[] = {{SIGINT, "parts/cap.off"}, {SIGINT, "-n 20 parts/cap.off"},
                {SIGTERM, "-n 20 --trials /dev/null parts/cap.off"}};
    for (int i = 0; i < 3; i++) {
        char *out;
        CHECK_INT(run_signalled(runs[i].sig, runs[i].args, &out), 128 + runs[i].sig);
        CHECK_INT((int)strlen(out), 0);
        free(out);
    }
    expect_failure("--dt 0.001 -n 10 parts/cap.off", 2, "--dt sets the time step of the ode and "
                   "bullet engines only");
    expect_failure("--engine impulse --dt 0.001 parts/cap.off", 2, "--dt");
    char *out, *err;
    CHECK_INT(run("--dt 0.002 --engine ode -n 5 parts/cap.off", &out, &err), 0);
    free(out);
    free(err);
}

/* eq16.awk, fed the paper's own columns, must reproduce the errors the paper
 * publishes (Table 1, the cap: QS 10.1, PQS 1.2, dynamic 4.0; Table 4, the
 * square button: 17.2, 10.7, 4.8), to the tables' 0.05 rounding. */
static void test_eq16(void)
{
    const char *parts[] = {"insulator_cap", "square_black_button"};
    const double want[2][3] = {{10.1, 1.2, 4.0}, {17.2, 10.7, 4.8}};
    const char *cols[] = {"p_qs", "p_pqs", "p"};
    for (int i = 0; i < 2; i++)
        for (int c = 0; c < 3; c++) {
            char cmd[512], *out, *err;
            snprintf(cmd, sizeof cmd,
                     "awk -F, -v part=%s 'NR == 1 { print \"pose,p_qs,p_pqs,p\" } $1 == part "
                     "{ print $2 \",\" $3 / 100 \",\" $4 / 100 \",\" $5 / 100 }' "
                     "parts/paper-tables.csv > %s/own.csv && awk -F, -v part=%s -v column=%s "
                     "-f scripts/eq16.awk parts/paper-tables.csv %s/own.csv",
                     parts[i], tmpdir, parts[i], cols[c], tmpdir);
            CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
            CHECK_NEAR(strtod(out, NULL), want[i][c], 0.05, "the paper's tables print one decimal");
            free(out);
            free(err);
        }
}

/* measured.awk's file of each of the paper's parts (what scripts/paper.sh -L
 * and scripts/figures.sh feed to posedrop fit and --measured) is read as
 * counts: the paper's percentages times its trials are not whole drops, and
 * a pose,p,n file of them was refused. Its counts are the shipped
 * parts/<part>-measured.csv's, and a fit of one evaluation reads it. */
static void test_measured_awk(void)
{
    const char *parts[] = {"insulator_cap", "white_button", "rect_black_button",
                           "square_black_button"};
    for (int i = 0; i < 4; i++) {
        char cmd[1024], *out, *err;
        snprintf(cmd, sizeof cmd,
                 PD_CLI_PATH " --group parts/%s.off > %s/grouped.csv && awk -F, -v part=%s "
                 "-v tag=test -f scripts/measured.awk parts/paper-tables.csv %s/grouped.csv > "
                 "%s/m.csv && cmp %s/m.csv parts/%s-measured.csv && " PD_CLI_PATH
                 " fit --fit mu=0.1:0.8 -n 10 --max-evals 1 --points 1 -j 1 --part parts/%s.off "
                 "--measured %s/m.csv",
                 parts[i], tmpdir, parts[i], tmpdir, tmpdir, tmpdir, parts[i], parts[i], tmpdir);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
        CHECK(out && strncmp(out, "part,role,pose,count,", 21) == 0);
        free(out);
        free(err);
    }
}

static void test_scripts(void)
{
    char cmd[512], *out, *err;
    /* make demo's words: the classes with the three estimates, one row
     * each (the cap: its sides and two ends), and where the report is. */
    snprintf(cmd, sizeof cmd, "scripts/demo.sh " PD_CLI_PATH " parts/cap.off %s/demo", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    CHECK(strstr(out, "  class poses      QS     PQS    drops   95% interval\n  1        32 ") &&
          strstr(out, "\n  3         1 ") && !strstr(out, "\n  4 ") && strstr(out, "/demo/cap.html"));
    free(out);
    free(err);
    char html[160];
    snprintf(html, sizeof html, "%s/demo/cap.html", tmpdir);
    CHECK(access(html, R_OK) == 0);
    snprintf(cmd, sizeof cmd, "scripts/posedrop-batch -o %s/batch -- parts/cap.off parts/button.off",
             tmpdir);
    int rc = run_cmd(cmd, 1, &out, &err);
    CHECK_INT(rc, 0);
    if (rc)
        printf("     %s", err);
    free(out);
    free(err);
    char path[160];
    snprintf(path, sizeof path, "%s/batch/all.csv", tmpdir);
    char *all = slurp(path);
    CHECK(all != NULL && strncmp(all, "part,pose,nx,ny,nz,area,height,p_qs,p_pqs\n", 42) == 0);
    CHECK(all != NULL && strstr(all, "\ncap,1,") != NULL && strstr(all, "\nbutton,1,") != NULL);
    free(all);

    /* A bad file among good ones: the batch reports it and fails; the good
     * part's result is written, and all.csv, which would not hold every
     * part, is not (there was none before). */
    snprintf(path, sizeof path, "%s/broken.off", tmpdir);
    write_file(path, "OFF\n8 1 0\n");
    snprintf(cmd, sizeof cmd, "scripts/posedrop-batch -o %s/batch2 -- parts/cap.off %s", tmpdir, path);
    rc = run_cmd(cmd, 1, &out, &err);
    CHECK(rc != 0);
    CHECK(strstr(err, "broken.off") != NULL);
    free(out);
    free(err);
    snprintf(path, sizeof path, "%s/batch2/cap.csv", tmpdir);
    all = slurp(path);
    CHECK(all != NULL && strstr(all, "\n1,") != NULL);
    free(all);
    snprintf(path, sizeof path, "%s/batch2/all.csv", tmpdir);
    CHECK(access(path, F_OK) != 0);

    /* The batch writes nothing onto what it reads or writes: a part where
     * its own results or messages go (DIR/x.err, DIR/y.csv replaced), a
     * part whose results would be all.csv, a side file every part's run
     * would write, a scene file as --trials. */
    char *cube = slurp("parts/canonical/cube.off");
    snprintf(cmd, sizeof cmd, "(mkdir -p %s/b3 && cp parts/canonical/cube.off %s/b3/x.err && "
             "cp parts/canonical/cube.off %s/b3/y.csv && cp parts/canonical/cube.off %s/all.off && "
             "echo 'mu = 0.4' >%s/b3.scene)", tmpdir, tmpdir, tmpdir, tmpdir, tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    const char *refused[][2] = {
        {"-o %s/b3 -- %s/b3/x.err", "is the same file as part"},
        {"-o %s/b3 -- %s/b3/y.csv", "is the same file as part"},
        {"-o %s/b4 -- %s/all.off", "(all results)"},
        {"-o %s/b5 --trials %s/t.csv -- parts/cap.off parts/button.off", "each of the 2 parts"},
        {"-o %s/b6 -n 5 --trials %s/b3.scene --scene %s/b3.scene -- parts/cap.off", "--scene"},
    };
    for (int i = 0; i < 5; i++) {
        char fmt[256];
        snprintf(fmt, sizeof fmt, "scripts/posedrop-batch %s", refused[i][0]);
        snprintf(cmd, sizeof cmd, fmt, tmpdir, tmpdir, tmpdir);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 2);
        if (!strstr(err, refused[i][1]))
            printf("     %s: %s", cmd, err);
        CHECK(strstr(err, refused[i][1]) != NULL);
        free(out);
        free(err);
    }
    const char *kept[] = {"b3/x.err", "b3/y.csv", "all.off"};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", tmpdir, kept[i]);
        char *now = slurp(path);
        CHECK(cube && now && strcmp(now, cube) == 0);
        free(now);
    }
    snprintf(path, sizeof path, "%s/b3.scene", tmpdir);
    char *sc = slurp(path);
    CHECK(sc && strcmp(sc, "mu = 0.4\n") == 0);
    free(sc);
    free(cube);
}

/* Column k (from 0) of a CSV row, as a number; the row is the line starting
 * at p. */
static double column(const char *p, int k)
{
    for (int i = 0; i < k && p; i++) {
        p = strchr(p, ',');
        p = p ? p + 1 : NULL;
    }
    return p ? strtod(p, NULL) : nan("");
}

/* --group: the cap's 32 sides are one class. Its row sums the ungrouped rows
 * of poses 3..34, for the static columns and (same seed, same drops) for the
 * drop counts. */
static void test_group(void)
{
    char *out, *err, *ref, *err2;
    csv_summary s;
    CHECK_INT(run("--group parts/cap.off", &out, &err), 0);
    const char *head = "pose,nx,ny,nz,area,height,p_qs,p_pqs,members\n";
    CHECK(strncmp(out, head, strlen(head)) == 0);
    CHECK(summarise(out, &s));
    CHECK_INT(s.nrows, 3);
    CHECK(s.numbered);
    CHECK_NEAR(s.p_qs_sum, 1.0, 1e-9, "10 printed digits per row");
    CHECK_NEAR(s.p_pqs_sum, 1.0, 1e-9, "10 printed digits per row");
    /* Classes most probable (summed QS) first: the 32 sides (QS 0.55)
     * before the caps, classes of one (0.23, 0.22). */
    CHECK(strstr(out, "\n2,") && strstr(out, ",1\n3,") != NULL && strstr(out, ",2\n") != NULL);
    char members[256] = "";
    for (int i = 3; i <= 34; i++)
        snprintf(members + strlen(members), sizeof members - strlen(members), "%s%d",
                 i > 3 ? " " : ",", i);
    strcat(members, "\n");
    CHECK(strstr(out, members) != NULL);
    CHECK_INT(run("parts/cap.off", &ref, &err2), 0);
    const char *row3 = strstr(out, "\n1,"); /* the sides' class */
    double qs = 0.0, pqs = 0.0;
    int rows = 0;
    for (const char *p = strchr(ref, '\n') + 1; *p; p = strchr(p, '\n') + 1, rows++)
        if (rows >= 2) {
            qs += column(p, 6);
            pqs += column(p, 7);
        }
    CHECK_INT(rows, 34);
    CHECK(row3 != NULL);
    if (row3) {
        CHECK_NEAR(column(row3 + 1, 6), qs, 1e-9, "10 printed digits per row");
        CHECK_NEAR(column(row3 + 1, 7), pqs, 1e-9, "10 printed digits per row");
    }
    free(out);
    free(err);
    free(ref);
    free(err2);

    CHECK_INT(run("--group -n 50 parts/cap.off", &out, &err), 0);
    CHECK_INT(run("-n 50 parts/cap.off", &ref, &err2), 0);
    const char *cols =
        "pose,nx,ny,nz,area,height,p_qs,p_pqs,n,count,p,ci_lo,ci_hi,unsettled,partial,members\n";
    CHECK(strncmp(out, cols, strlen(cols)) == 0);
    long count = 0, total = 0, side_count = 0;
    rows = 0;
    for (const char *p = strchr(out, '\n') + 1; *p; p = strchr(p, '\n') + 1, rows++)
        total += (long)column(p, 9);
    CHECK_INT(rows, 3);
    for (const char *p = strchr(ref, '\n') + 1; *p; p = strchr(p, '\n') + 1, count++)
        if (count >= 2)
            side_count += (long)column(p, 9);
    row3 = strstr(out, "\n1,");
    CHECK(row3 != NULL);
    if (row3) {
        CHECK_INT((long)column(row3 + 1, 9), side_count);
        CHECK_NEAR(column(row3 + 1, 10), side_count / 50.0, 1e-10, "10 printed digits");
        /* The class's own Wilson interval holds its p. */
        CHECK(column(row3 + 1, 11) < column(row3 + 1, 10));
        CHECK(column(row3 + 1, 12) > column(row3 + 1, 10));
    }
    CHECK_INT(total + (long)column(strchr(out, '\n') + 1, 13), 50);
    free(out);
    free(err);
    free(ref);
    free(err2);

    CHECK_INT(run("--help", &out, &err), 0);
    CHECK(strstr(out, "--group") != NULL);
    free(out);
    free(err);
    expect_failure("--group --facets parts/cap.off", 2, "--group");
}

/* The position (from 0) of the column named name in the header line that
 * starts csv, or -1. */
static int column_index(const char *csv, const char *name)
{
    size_t len = strlen(name);
    int k = 0;
    for (const char *p = csv; p && *p && *p != '\n'; k++) {
        if (strncmp(p, name, len) == 0 && (p[len] == ',' || p[len] == '\n'))
            return k;
        p = strpbrk(p, ",\n");
        p = p && *p == ',' ? p + 1 : NULL;
    }
    return -1;
}

/* Tallies column `name` of every data row of a CSV text into tally[0..max]
 * (values outside go to bad). Returns the number of data rows, -1 if there
 * is no such column. */
static int tally_column(const char *csv, const char *name, long *tally, int max, int *bad)
{
    int k = csv ? column_index(csv, name) : -1, rows = 0;
    *bad = 0;
    if (k < 0)
        return -1;
    memset(tally, 0, sizeof *tally * (size_t)(max + 1));
    for (const char *p = strchr(csv, '\n'); p && p[1]; p = strchr(p + 1, '\n'), rows++) {
        double v = column(p + 1, k);
        if (v >= 0 && v <= max && v == (int)v)
            tally[(int)v]++;
        else
            ++*bad;
    }
    return rows;
}

/* --trials with and without --group, from the same seed (so the same drops):
 * the trials' pose column joins the main output's rows, class numbers with
 * --group and pose numbers without. Per-pose tallies of the trials equal the
 * output's count column exactly (integers), the unsettled drops are pose 0,
 * and each drop's member is its ungrouped pose and one of its class's
 * members. */
static void test_group_trials(void)
{
    char *out, *err, *gout, *gerr, args[512], tpath[160], gpath[160];
    enum { N = 60, MAXP = 64 };
    snprintf(tpath, sizeof tpath, "%s/trials_plain.csv", tmpdir);
    snprintf(gpath, sizeof gpath, "%s/trials_group.csv", tmpdir);
    snprintf(args, sizeof args, "-n %d --trials %s parts/cap.off", N, tpath);
    CHECK_INT(run(args, &out, &err), 0);
    snprintf(args, sizeof args, "-n %d --group --trials %s parts/cap.off", N, gpath);
    CHECK_INT(run(args, &gout, &gerr), 0);
    char *t = slurp(tpath), *g = slurp(gpath);
    CHECK(t && strncmp(t, "drop,qw,qx,qy,qz,pose,collisions,time,end,partial\n", 50) == 0);
    const char *ghead = "drop,qw,qx,qy,qz,pose,collisions,time,end,member,partial\n";
    CHECK(g && strncmp(g, ghead, strlen(ghead)) == 0);

    /* Each file against its own main output: row r of the output is pose
     * (class) r, its count column the drops that settled there. */
    const char *csv[2] = {out, gout}, *trials[2] = {t, g};
    int nrows_out[2] = {0, 0};
    for (int grouped = 0; grouped < 2; grouped++) {
        long tally[MAXP + 1];
        int bad, rows = tally_column(trials[grouped], "pose", tally, MAXP, &bad);
        CHECK_INT(rows, N);
        CHECK_INT(bad, 0);
        int kc = column_index(csv[grouped], "count"), ku = column_index(csv[grouped], "unsettled");
        CHECK(kc >= 0 && ku >= 0);
        int r = 0, counts_ok = 1;
        for (const char *p = strchr(csv[grouped], '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
            r++;
            counts_ok &= r <= MAXP && (long)column(p + 1, 0) == r &&
                         (long)column(p + 1, kc) == tally[r];
            if (r == 1)
                CHECK_INT(tally[0], (long)column(p + 1, ku));
        }
        CHECK(counts_ok);
        /* No trial names a pose (class) the output does not have. */
        long beyond = 0;
        for (int i = r + 1; i <= MAXP; i++)
            beyond += tally[i];
        CHECK_INT(beyond, 0);
        nrows_out[grouped] = r;
    }
    CHECK_INT(nrows_out[0], 34); /* the cap: 34 poses in 3 classes */
    CHECK_INT(nrows_out[1], 3);

    /* Drop by drop: member = the ungrouped pose, and a member of its class. */
    int kp = column_index(g, "pose"), km = column_index(g, "member"), kt = column_index(t, "pose");
    int kmem = column_index(gout, "members");
    CHECK(kp >= 0 && km >= 0 && kt >= 0 && kmem >= 0);
    int same = 1, listed = 1, drops = 0;
    const char *pt = strchr(t, '\n'), *pg = strchr(g, '\n');
    for (; pt && pt[1] && pg && pg[1]; pt = strchr(pt + 1, '\n'), pg = strchr(pg + 1, '\n')) {
        drops++;
        int cls = (int)column(pg + 1, kp), member = (int)column(pg + 1, km);
        same &= member == (int)column(pt + 1, kt);
        if (cls == 0) {
            listed &= member == 0;
            continue;
        }
        /* The members column of row cls: space-separated pose numbers. */
        const char *row = gout;
        for (int i = 0; i < cls && row; i++)
            row = strchr(row + 1, '\n');
        const char *m = row ? row + 1 : NULL;
        for (int i = 0; i < kmem && m; i++)
            m = strchr(m, ',') ? strchr(m, ',') + 1 : NULL;
        int found = 0;
        for (char *e; m && *m && *m != '\n'; m = e) {
            long v = strtol(m, &e, 10);
            if (e == m)
                break;
            found |= v == member;
        }
        listed &= found;
    }
    CHECK_INT(drops, N);
    CHECK(same);
    CHECK(listed);
    free(t);
    free(g);
    free(out);
    free(err);
    free(gout);
    free(gerr);
}

/* Sums column k (0-based) of every data row of a CSV text. */
static double column_sum(const char *csv, int k, int *rows)
{
    double sum = 0.0;
    *rows = 0;
    for (const char *p = strchr(csv, '\n'); p && p[1]; p = strchr(p + 1, '\n'), ++*rows)
        sum += column(p + 1, k);
    return sum;
}

/* --initial stationary: the same columns with p the chain's long run, the
 * same bytes for any thread count, the matrix in --transitions, classes
 * summed by --group, and the combinations it refuses. */
static void test_stationary(void)
{
    char *out, *err, *out2, *err2, args[512], path[160];
    int rows;
    /* The cube, 140 drops: 20 uniform, 20 resting on each of its 6 faces. */
    snprintf(path, sizeof path, "%s/transitions.csv", tmpdir);
    snprintf(args, sizeof args,
             "-n 140 -j 1 --initial stationary --verbose --transitions %s parts/canonical/cube.off",
             path);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK_INT(run("-n 140 -j 2 --initial stationary parts/canonical/cube.off", &out2, &err2), 0);
    const char *cols = "pose,nx,ny,nz,area,height,p_qs,p_pqs,n,count,p,ci_lo,ci_hi,unsettled,partial\n";
    CHECK(strncmp(out, cols, strlen(cols)) == 0);
    CHECK(strcmp(out, out2) == 0);
    CHECK_NEAR(column_sum(out, 10, &rows), 1.0, 6e-10, "10 printed digits on 6 rows");
    CHECK_INT(rows, 6);
    CHECK_NEAR(column_sum(out, 9, &rows), 140 - column(strchr(out, '\n') + 1, 13), 0.0,
               "every settled drop counted once");
    CHECK(strstr(err, "20 uniform drops, 20 resting on each of 6 poses") != NULL);
    CHECK(strstr(err, "closed class") != NULL && strstr(err, "total variation") != NULL);
    char *t = slurp(path);
    CHECK(t && strncmp(t, "from_pose,to_pose,count,p\n", 26) == 0);
    if (t) {
        /* 7 rows of 6: the uniform drops' outcomes, then each face's; the
         * faces' rows hold the 120 drops started on them (none unsettled
         * on a cube), each row's p sums to 1. */
        CHECK_NEAR(column_sum(t, 2, &rows), 140, 0.0, "all drops settle on a cube");
        CHECK_INT(rows, 42);
        CHECK_NEAR(column_sum(t, 3, &rows), 7.0, 7 * 6e-10, "10 printed digits, 7 rows of P");
        CHECK(strstr(t, "\n0,1,") != NULL && strstr(t, "\n6,6,") != NULL);
    }
    free(t);
    free(out);
    free(err);
    free(out2);
    free(err2);

    /* --group on a 1 x 1 x 2 box (ends and sides): each class's p is the sum
     * of its poses' p, the matrix is between classes. */
    snprintf(args, sizeof args,
             "-n 140 --initial stationary --group --transitions %s parts/canonical/box_1x1x2.off",
             path);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK_INT(run("-n 140 --initial stationary parts/canonical/box_1x1x2.off", &out2, &err2), 0);
    double grouped = column_sum(out, 10, &rows);
    CHECK_INT(rows, 2);
    CHECK_NEAR(grouped, column_sum(out2, 10, &rows), 1e-9, "10 printed digits per row");
    t = slurp(path);
    CHECK(t != NULL);
    if (t) {
        column_sum(t, 2, &rows);
        CHECK_INT(rows, 6);
    }
    free(t);
    free(out);
    free(err);
    free(out2);
    free(err2);

    expect_failure("--initial stationary --ci 0.05 parts/cap.off", 2, "--ci");
    expect_failure("--transitions /tmp/x.csv -n 10 parts/cap.off", 2, "--transitions");
    expect_failure("--initial stationary -n 300 parts/cap.off", 2, "at least 350 drops");
}

/* posedrop ARGS (through the shell: a pipe may follow) must exit 0 and warn
 * on stderr with warning (NULL: stay silent there); stdout is a result, with
 * no warning in it. Returns stdout (caller frees). */
static char *expect_warning(const char *args, const char *warning)
{
    char cmd[1024], *out, *err;
    snprintf(cmd, sizeof cmd, "{ %s %s; }", PD_CLI_PATH, args); /* stderr of the whole pipe */
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    int ok = warning ? strstr(err, warning) != NULL : err[0] == '\0';
    if (!ok)
        printf("     stderr of '%s' should %s%s:\n     %s\n", args, warning ? "say " : "be empty",
               warning ? warning : "", err);
    CHECK(ok);
    CHECK(strncmp(out, "pose,", 5) == 0 && strstr(out, "warning") == NULL);
    free(err);
    return out;
}

/* A cube of side a metres (a sqrt 3 across) in tmpdir/name. */
static const char *cube_file(const char *name, double a)
{
    static char path[256];
    char text[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, name);
    snprintf(text, sizeof text,
             "OFF\n8 6 0\n0 0 0\n%.17g 0 0\n%.17g %.17g 0\n0 %.17g 0\n0 0 %.17g\n"
             "%.17g 0 %.17g\n%.17g %.17g %.17g\n0 %.17g %.17g\n"
             "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n",
             a, a, a, a, a, a, a, a, a, a, a, a);
    CHECK(write_file(path, text));
    return path;
}

/* A part outside the sizes a dropped part has (0.5 mm to 2 m across) or a
 * drop height out of proportion to it (over 100 or under 0.1 part sizes)
 * warns on stderr without --verbose, naming the unit to try, and the run
 * goes on: stdout is what it would be without the warning. The poses'
 * normals and probabilities do not depend on the unit, so a file read in
 * the wrong unit prints those columns exactly as in the right one (the
 * lengths' columns, area and height, are cut). */
static void test_scale_warnings(void)
{
    /* hexnut.obj is in millimetres (20.9 mm across), cap.off in metres. */
    static const struct {
        const char *wrong, *right, *warning;
    } units[] = {
        {"parts/hexnut.obj", "--units mm parts/hexnut.obj",
         "posedrop: warning: parts/hexnut.obj: the part is 20.9 m across; if the file is in "
         "millimetres, add --units mm"},
        {"--units mm parts/cap.off", "parts/cap.off",
         "the part is 0.0354 mm across; if the file is in metres, give --units m, not --units mm"},
    };
    for (int k = 0; k < 2; k++) {
        char wrong[256], right[256];
        snprintf(wrong, sizeof wrong, "%s | cut -d, -f1-4,7-", units[k].wrong);
        snprintf(right, sizeof right, "%s | cut -d, -f1-4,7-", units[k].right);
        char *a = expect_warning(wrong, units[k].warning), *b = expect_warning(right, NULL);
        CHECK(strcmp(a, b) == 0);
        free(a);
        free(b);
    }
    /* No unit makes a 0.17 mm cube in metres larger: the warning asks. */
    char args[512];
    snprintf(args, sizeof args, "%s", cube_file("tiny.off", 1e-4));
    free(expect_warning(args, "the part is 0.173 mm across; is that what you meant?"));
    /* The thresholds: 1.905 and 2.165 m across; 0.520 and 0.485 mm. */
    free(expect_warning(cube_file("c1.off", 1.1), NULL));
    free(expect_warning(cube_file("c2.off", 1.25), "the part is 2.17 m across; if the file is in "
                                                   "millimetres, add --units mm"));
    free(expect_warning(cube_file("c3.off", 3e-4), NULL));
    free(expect_warning(cube_file("c4.off", 2.8e-4), "the part is 0.485 mm across"));
    /* Heights against the 20.9 mm nut: 95.7 and 105 sizes, 0.105 and 0.0957;
     * 0 (set down on purpose) is not warned about, nor a height when the
     * part's size already is (the likelier cause of both). */
    static const struct {
        const char *h, *warning;
    } heights[] = {
        {"2.0", NULL},
        {"2.2", "the drop height, 2.2 m, is 105 times the part's size (20.9 mm across): more a "
                "throw than a drop; -h is in metres, whatever --units says"},
        {"120", "the drop height, 120 m, is 5743 times the part's size"},
        {"0.0022", NULL},
        {"0.002", "the drop height, 2 mm, is 0.0957 times the part's size (20.9 mm across): the "
                  "part is set down more than dropped"},
        {"0", NULL},
    };
    for (size_t k = 0; k < sizeof heights / sizeof *heights; k++) {
        snprintf(args, sizeof args, "--units mm -n 20 -h %s parts/hexnut.obj", heights[k].h);
        free(expect_warning(args, heights[k].warning));
    }
    char *out, *err;
    CHECK_INT(run("-n 20 parts/hexnut.obj", &out, &err), 0);
    CHECK(strstr(err, "the part is 20.9 m across") && !strstr(err, "drop height"));
    free(out);
    free(err);
}

/* Lines of text that end with `tail` (a trials file's end column). */
static int rows_ending(const char *text, const char *tail)
{
    int n = 0;
    size_t len = strlen(tail);
    for (const char *c = text; c && (c = strstr(c, tail)) != NULL; c += len)
        n += c[len] == '\n';
    return n;
}

/* --time-limit: the drops run with it, stderr says how many it ended and
 * at what time, and each such drop says so in the trials' end column (exit
 * 0: a limit is an answer about the part, not a failure). A bad value is
 * refused, and so is a run whose limit a stepping engine could only reach
 * in more steps than it may take (a 1e29 m cube's automatic limit). */
static void test_time_limit(void)
{
    expect_failure("--time-limit 0 -n 3 parts/cap.off", 2, "--time-limit");
    expect_failure("--time-limit soon -n 3 parts/cap.off", 2, "expected auto or a time in s");
    expect_failure("--time-limit inf -n 3 parts/cap.off", 2, "--time-limit");
    char args[256], trials[160], path[160], *out, *err;
    snprintf(trials, sizeof trials, "%s/limited.csv", tmpdir);
    snprintf(args, sizeof args, "--time-limit 0.05 -n 4 --trials %s parts/cap.off", trials);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(err && strstr(err, "4 of 4 drops did not settle") &&
          strstr(err, "4 at the time limit (0.05 s simulated"));
    /* The rows' p is count / n: with every drop unsettled it sums to 0,
     * said beside the rows. */
    CHECK(err && strstr(err, "(p sums to 0, not 1)"));
    char *t = slurp(trials);
    CHECK_INT(rows_ending(t, ",time_limit,0"), 4);
    free(t);
    free(out);
    free(err);
    CHECK_INT(run("--time-limit auto -n 4 parts/cap.off", &out, &err), 0);
    CHECK(out && strstr(out, ",4,") != NULL);
    free(out);
    free(err);
    snprintf(path, sizeof path, "%s/giant.off", tmpdir);
    write_file(path, "OFF\n8 6 0\n0 0 0\n1e29 0 0\n1e29 1e29 0\n0 1e29 0\n0 0 1e29\n"
                     "1e29 0 1e29\n1e29 1e29 1e29\n0 1e29 1e29\n4 0 3 2 1\n4 4 5 6 7\n"
                     "4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n");
    snprintf(args, sizeof args, "--engine ode --dt 0.001 -n 2 %s", path);
    expect_failure(args, 2, "steps of 0.001 s per drop");
    /* The automatic step is never refused: it is not taken shorter than
     * the time limit over PD_STEPS_MAX. */
    snprintf(args, sizeof args, "--engine ode -n 2 %s", path);
    CHECK_INT(run(args, &out, &err), 0);
    CHECK(out && strstr(out, ",2,") != NULL);
    free(out);
    free(err);
}

/* Scene options without drops warn that they change nothing (QS and PQS
 * depend on the part alone); a contact time as one multiple of auto, 3x,
 * is read as 0.3x:3x is; the report says beside its table that p no
 * longer sums to 1 when drops did not settle. */
static void test_scene_words(void)
{
    free(expect_warning("--mu 0.2:0.6 parts/cap.off",
                        "--mu (like every scene option) applies to drops, and none are run"));
    char args[512], path[160];
    snprintf(path, sizeof path, "%s/s.scene", tmpdir);
    write_file(path, "mu = 0.5\n");
    snprintf(args, sizeof args, "--scene %s parts/cap.off", path);
    free(expect_warning(args, "--scene (like every scene option) applies to drops"));
    free(expect_warning("-n 5 --mu 0.2:0.6 parts/cap.off", NULL));
    free(expect_warning("parts/cap.off", NULL));
    /* 3x: three times the part's auto duration, the bytes of the range
     * 3x:3x (every drop draws 3). */
    char *a = expect_warning("-n 8 --contact-time 3x parts/cap.off", NULL);
    char *b = expect_warning("-n 8 --contact-time 3x:3x parts/cap.off", NULL);
    CHECK(strcmp(a, b) == 0);
    free(a);
    free(b);
    snprintf(path, sizeof path, "%s/limited.html", tmpdir);
    snprintf(args, sizeof args, "--time-limit 0.05 -n 4 --report %s parts/cap.off", path);
    char *out, *err;
    CHECK_INT(run(args, &out, &err), 0);
    char *html = slurp(path);
    CHECK(html && strstr(html, "4 of 4 drops did not settle") &&
          strstr(html, "the dynamic column sums to 0.0%, not 100%"));
    free(html);
    free(out);
    free(err);
}

/* --scene and --measured naming a named pipe that no program writes to:
 * refused at once (exit 2, the pipe named, nothing on stdout) as the part
 * is, where they waited in open() for ever; `timeout` ends a regression
 * with 124 instead of hanging the suite. A pipe with its writer there is
 * read as before. */
static void test_fifo_inputs(void)
{
    char fifo[160], cmd[512], *out, *err;
    snprintf(fifo, sizeof fifo, "%s/nowriter", tmpdir);
    CHECK(mkfifo(fifo, 0600) == 0);
    const char *opts[] = {"--scene", "--chart /dev/null --measured"};
    for (int i = 0; i < 2; i++) {
        snprintf(cmd, sizeof cmd, "timeout 60 %s -n 5 %s %s parts/cap.off", PD_CLI_PATH, opts[i],
                 fifo);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 2);
        CHECK_INT((int)strlen(out), 0);
        if (!strstr(err, "a named pipe that gave nothing to read"))
            printf("     %s: %s", cmd, err);
        CHECK(strstr(err, "nowriter: a named pipe that gave nothing to read") != NULL);
        free(out);
        free(err);
    }
    snprintf(cmd, sizeof cmd, "printf 'mu = 0.4\\n' | timeout 60 %s --scene /dev/stdin -n 5 "
             "--trials /dev/null parts/cap.off", PD_CLI_PATH);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    CHECK(strstr(out, "pose,") == out);
    free(out);
    free(err);
    remove(fifo);
}

/* The value in column name of data row r (from 0) of a CSV text; NaN when
 * the column or row is missing, or the field is empty. */
static double cell(const char *csv, const char *name, int r)
{
    int k = csv ? column_index(csv, name) : -1;
    const char *p = k >= 0 ? strchr(csv, '\n') : NULL;
    for (int i = 0; i < r && p; i++)
        p = strchr(p + 1, '\n');
    if (!p || !p[1])
        return nan("");
    p++;
    for (int i = 0; i < k && p; i++) {
        p = strpbrk(p, ",\n");
        p = p && *p == ',' ? p + 1 : NULL;
    }
    return p && *p != ',' && *p != '\n' ? strtod(p, NULL) : nan("");
}

static int data_rows(const char *csv)
{
    int rows = 0;
    for (const char *p = strchr(csv, '\n'); p && p[1]; p = strchr(p + 1, '\n'))
        rows++;
    return rows;
}

/* --crosscheck: each engine's column is that engine's own run from the same
 * seed (the same releases), exactly; the lowest and highest are theirs; the
 * disagreement flag is the separate runs' 95% intervals apart; the bytes do
 * not depend on -j; JSON and the report carry the same, and the options it
 * refuses. The cap at ODE's and Bullet's old fixed step of 1 ms, far from
 * converged (engines apart on some classes), and the button at the automatic
 * step (apart on none at 30 drops) between them exercise both words. */
static void test_crosscheck(void)
{
    static const char *const engines[] = {"impulse", "ode", "bullet"};
    static const char *const cols[] = {"p_impulse", "p_ode", "p_bullet"};
    static const char *const parts[] = {"parts/cap.off", "parts/button.off"};
    static const char *const steps[] = {"--dt 0.001 ", ""};
    char args[512], *out, *err, *out2, *err2, *own[3], *own_err[3];
    int saw_apart = 0, saw_agree = 0;
    for (int part = 0; part < 2; part++) {
        snprintf(args, sizeof args, "-n 30 -j 1 --group --crosscheck %s%s", steps[part], parts[part]);
        CHECK_INT(run(args, &out, &err), 0);
        snprintf(args, sizeof args, "-n 30 -j 3 --group --crosscheck %s%s", steps[part], parts[part]);
        CHECK_INT(run(args, &out2, &err2), 0);
        CHECK(strcmp(out, out2) == 0); /* any thread count, the same bytes */
        free(out2);
        free(err2);
        for (int k = 0; k < 3; k++) {
            snprintf(args, sizeof args, "-n 30 --group --engine %s %s%s", engines[k],
                     k ? steps[part] : "", parts[part]);
            CHECK_INT(run(args, &own[k], &own_err[k]), 0);
        }
        CHECK(column_index(out, "members") > column_index(out, "engines_disagree"));
        int rows = data_rows(out), apart_rows = 0;
        CHECK(rows >= 2);
        CHECK_INT(data_rows(own[0]), rows);
        for (int r = 0; r < rows; r++) {
            double lo = 2.0, hi = -1.0, min_hi = 2.0, max_lo = -1.0;
            for (int k = 0; k < 3; k++) {
                double p = cell(own[k], "p", r);
                CHECK(cell(out, cols[k], r) == p); /* the same releases, the same outcomes */
                lo = fmin(lo, p);
                hi = fmax(hi, p);
                min_hi = fmin(min_hi, cell(own[k], "ci_hi", r));
                max_lo = fmax(max_lo, cell(own[k], "ci_lo", r));
            }
            CHECK(cell(out, "p", r) == cell(out, "p_impulse", r)); /* --engine's p stays */
            CHECK(cell(out, "p_engine_min", r) == lo);
            CHECK(cell(out, "p_engine_max", r) == hi);
            int apart = min_hi < max_lo;
            CHECK_INT((int)cell(out, "engines_disagree", r), apart);
            apart_rows += apart;
        }
        CHECK(strstr(err, apart_rows ? "engines disagree beyond their 95% intervals on"
                                     : "engines agree within their 95% intervals") != NULL);
        saw_apart |= apart_rows > 0;
        saw_agree |= apart_rows == 0;
        for (int k = 0; k < 3; k++) {
            free(own[k]);
            free(own_err[k]);
        }
        free(out);
        free(err);
    }
    CHECK(saw_apart && saw_agree);

    /* Another --engine: p is its own, the columns the same; --dt reaches ODE
     * and Bullet. */
    CHECK_INT(run("-n 20 --engine ode --crosscheck parts/button.off", &out, &err), 0);
    CHECK(cell(out, "p", 0) == cell(out, "p_ode", 0));
    free(out);
    free(err);
    CHECK_INT(run("-n 20 --dt 0.0005 --crosscheck parts/cap.off", &out, &err), 0);
    CHECK_INT(run("-n 20 --dt 0.0005 --engine bullet parts/cap.off", &out2, &err2), 0);
    for (int r = 0; r < data_rows(out); r++)
        CHECK(cell(out, "p_bullet", r) == cell(out2, "p", r));
    free(out);
    free(err);
    free(out2);
    free(err2);

    /* JSON: the same keys in every row, and what each engine ran. */
    CHECK_INT(run("-n 20 --crosscheck --group --format json parts/cap.off", &out, &err), 0);
    const char *keys[] = {"\"p_impulse\": ", "\"p_ode\": ", "\"p_bullet\": ", "\"p_engine_min\": ",
                          "\"p_engine_max\": ", "\"engines_disagree\": ", "\"crosscheck\": {"};
    for (size_t i = 0; i < sizeof keys / sizeof keys[0]; i++)
        CHECK(strstr(out, keys[i]) != NULL);
    free(out);
    free(err);

    /* The report: the band in the chart, the section in words. */
    char report[160];
    snprintf(report, sizeof report, "%s/crosscheck.html", tmpdir);
    snprintf(args, sizeof args, "-n 20 --dt 0.001 --crosscheck --group --report %s parts/cap.off",
             report);
    CHECK_INT(run(args, &out, &err), 0);
    char *html = slurp(report);
    CHECK(html != NULL);
    if (html) {
        CHECK(strstr(html, "<section id=\"crosscheck\">") != NULL);
        CHECK(strstr(html, "disagree beyond their sampling intervals") != NULL);
        CHECK(strstr(html, "the range across the engines") != NULL);
        CHECK(strstr(html, "stroke-dasharray=\"3 2\"") != NULL);
    }
    free(html);
    free(out);
    free(err);

    expect_failure("--crosscheck parts/cap.off", 2, "--crosscheck");
    expect_failure("--crosscheck -n 10 --shard 1/2 parts/cap.off", 2, "--crosscheck");
}

/* Nothing lost: a run that fails (stdout on a full disk) or is stopped
 * leaves every file it would have replaced as it was, or, interrupted,
 * writes its side files marked partial in their own content; posedrop fit
 * stops within the drops in flight of SIGINT/SIGTERM (130/143) and writes
 * nothing; an output naming a named pipe that no program reads is refused
 * at once instead of waiting in open(); merge of an endless binary input
 * stops at its first NUL byte, and of an endless line at 16 MiB. Each
 * script exits with the command's status, or 99 when a file was harmed
 * (the runs of 10^6 drops take minutes: the signal always comes first). */
typedef struct {
    const char *script;
    int code;
    const char *mention;
} script_case;

/* Each script run in a directory of its own with B the command, P the cap,
 * M a measured table of three classes: its exit status and a mention in
 * its stderr. */
static void run_scripts(const char *tag, const script_case *cases, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        char cmd[2048], *out, *err;
        snprintf(cmd, sizeof cmd, "(R=$PWD; B=$R/" PD_CLI_PATH "; P=$R/parts/cap.off; D=%s/%s%zu; "
                 "mkdir -p $D && cd $D && printf 'pose,count\\n1,30\\n2,20\\n3,10\\n' >m.csv && "
                 "M=$D/m.csv && %s)", tmpdir, tag, k, cases[k].script);
        int rc = run_cmd(cmd, 1, &out, &err);
        if (rc != cases[k].code || !strstr(err, cases[k].mention))
            printf("     %s case %zu: exit %d, expected %d with '%s':\n%s", tag, k, rc,
                   cases[k].code, cases[k].mention, err);
        CHECK_INT(rc, cases[k].code);
        CHECK(strstr(err, cases[k].mention) != NULL);
        free(out);
        free(err);
    }
}

static void test_nothing_lost(void)
{
    static const script_case cases[] = {
        {"echo OLD >t.csv; echo OLD >s.svg; $B -n 20 --trials t.csv --svg s.svg $P >/dev/full; "
         "r=$?; test \"$(cat t.csv)$(cat s.svg)\" = OLDOLD || exit 99; exit $r", 1,
         "error writing the output"},
        {"X=$R/parts/canonical/box_1x2x3.off; $B -n 140 --initial stationary --shard 1/2 $X >s1; "
         "$B -n 140 --initial stationary --shard 2/2 $X >s2; "
         "echo OLD >tr.csv; "
         "$B merge --transitions tr.csv s1 s2 >/dev/full; r=$?; "
         "test \"$(cat tr.csv)\" = OLD || exit 99; exit $r", 1, "error writing the output"},
        {"echo OLD >o.scene; echo OLD >p.csv; echo OLD >g.csv; $B fit --fit mu=0.2:0.6 -n 10 "
         "--max-evals 1 --points 2 --part $P --measured $M --out o.scene --params p.csv "
         "--gof g.csv >/dev/full; r=$?; test \"$(cat o.scene p.csv g.csv)\" = \"$(printf "
         "'OLD\\nOLD\\nOLD')\" || exit 99; exit $r", 1, "fit: error writing the output"},
        {"timeout --preserve-status -s INT 2 $B -n 1000000 -j 2 --trials t.csv --sensitivity "
         "se.csv --chart c.svg --mu 0.2:0.6 $P >/dev/null; r=$?; tail -n 1 t.csv | grep -q ',1$' "
         "&& tail -n 1 se.csv | grep -q ',1$' && grep -q 'interrupted: partial' c.svg || exit 99; "
         "exit $r", 130, "results are partial"},
        {"echo OLD >p.csv; timeout --preserve-status -s INT 2 $B fit --fit mu=0.2:0.6 -n 1000000 "
         "--part $P --measured $M --params p.csv; r=$?; test \"$(cat p.csv)\" = OLD && "
         "test -z \"$(ls -a | grep posedrop-)\" || exit 99; exit $r", 130,
         "fit: interrupted: nothing written"},
        {"timeout --preserve-status -s TERM 2 $B fit --fit mu=0.2:0.6 -n 1000000 --part $P "
         "--measured $M >out.csv; r=$?; test ! -s out.csv || exit 99; exit $r", 143,
         "fit: interrupted"},
        {"mkfifo f1; timeout -s KILL 20 $B -n 5 --trials f1 $P", 2,
         "f1: cannot write: a named pipe that no program is reading"},
        {"mkfifo f2; timeout -s KILL 20 $B fit --fit mu=0.2:0.6 --part $P --measured $M --gof f2", 2,
         "f2: cannot write: a named pipe that no program is reading"},
        {"mkfifo f3; cat f3 >got & $B -n 5 --trials f3 $P >/dev/null; r=$?; wait; "
         "test \"$(wc -l <got)\" = 6 || exit 99; exit $r", 0, ""},
        {"timeout -s KILL 60 $B merge /dev/zero", 2, "/dev/zero:1: not a shard: a NUL byte"},
        {"head -c 17000000 /dev/zero | tr '\\000' x >long; $B merge long", 2,
         "long:1: not a shard: a line longer than 16777216 bytes"},
    };
    run_scripts("lost", cases, sizeof cases / sizeof *cases);
}

/* posedrop fit's failures and messages: a part too small for its drop
 * height (a 1e-12 m cube from 0.12 m, whose every drop failed while the fit
 * printed an optimum of the smoothing alone and exited 0) is an input
 * error naming the ratio, for the fit and the main command alike; option
 * errors name the option; a measured
 * class beyond the part's is called a class; a one-class fit says there is
 * nothing to test instead of "df -1, p = 1"; a measured table with p not a
 * whole number of its n drops is refused. */
static void test_fit_messages(void)
{
    static const script_case cases[] = {
        {"awk '/^#/||/^OFF/{print;next} !h{print;h=1;next} NF==3{printf \"%.17g %.17g %.17g\\n\", "
         "$1*1e-10,$2*1e-10,$3*1e-10;next} {print}' $R/parts/canonical/cube.off >tiny.off; "
         "printf 'pose,count\\n1,5\\n' >one.csv; $B fit --fit mu=0.2:0.6 -n 10 --max-evals 2 "
         "--points 2 --part tiny.off --measured one.csv >out.csv; r=$?; test ! -s out.csv || "
         "exit 99; $B -n 5 tiny.off >>out.csv && exit 98; test ! -s out.csv || exit 99; exit $r",
         2, "is 6.93e+10 times the part's size (1.73e-12 m), more than the 1e+06"},
        {"$B fit -n 0 --fit mu=0.2:0.6 --part $P --measured $M", 2,
         "fit: -n: expected a number of drops"},
        {"$B fit --seed x --fit mu=0.2:0.6 --part $P --measured $M", 2, "fit: --seed: expected"},
        {"printf 'pose,count\\n1,5\\n2,3\\n' >two.csv; $B fit --fit mu=0.2:0.6 --part "
         "$R/parts/canonical/cube.off --measured two.csv", 2,
         "has 1 pose class (numbered as 'posedrop --group' numbers them"},
        {"printf 'pose,count\\n1,5\\n' >one.csv; $B fit --fit mu=0.2:0.6 -n 10 --max-evals 2 "
         "--points 2 --part $R/parts/canonical/cube.off --measured one.csv >/dev/null", 0,
         "the data cannot test this fit"},
        {"printf 'pose,p,n\\n1,0.333,10\\n2,0.667,10\\n' >pn.csv; $B fit --fit mu=0.2:0.6 "
         "--part $P --measured pn.csv", 2, "p 0.333 of n 10 drops is 3.33 drops"},
        /* A tumble that spins a 1 cm cube's corners at 87 m/s, 56 times its
         * landing speed, is said before a run of minutes a drop. */
        {"$B -n 1 --tumble 10000 --time-limit 0.01 $R/parts/canonical/cube.off >/dev/null", 0,
         "--tumble 10000 rad/s turns the part's corners at 86.6 m/s, 56 times"},
    };
    run_scripts("fitmsg", cases, sizeof cases / sizeof *cases);
}

void suite_cli(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-cli-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        CHECK(!"cannot create a temporary directory");
        return;
    }
    if (access(PD_CLI_PATH, X_OK) != 0) {
        printf("     %s not built\n", PD_CLI_PATH);
        CHECK(!"posedrop binary missing");
        return;
    }
    test_usage();
    test_bad_input();
    test_results();
    test_dynamic();
    test_output_paths();
    test_same_file();
    test_early_signal();
    test_eq16();
    test_measured_awk();
    test_scripts();
    test_group();
    test_group_trials();
    test_stationary();
    test_scale_warnings();
    test_time_limit();
    test_scene_words();
    test_fifo_inputs();
    test_crosscheck();
    test_nothing_lost();
    test_fit_messages();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0)
        printf("     could not remove %s\n", tmpdir);
}
