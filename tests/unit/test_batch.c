/* test_batch.c: runs split over processes give the unsplit run's bytes.
 * Shards K = 1..N merged (posedrop merge) against the run without --shard,
 * byte for byte, for uniform and stationary starts; every refusal of merge;
 * SIGTERM; the progress line; --format json read back by a real JSON parser;
 * the Slurm script against a stub sbatch; posedrop-mpi under mpirun when
 * OpenMPI is installed (make check builds it then). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>
#include "check.h"
#include "cli_run.h"
#include "suites.h"

#define BOX "parts/canonical/box_1x2x3.off"

/* Runs args with --shard K/N for K = 1..N into tmpdir/<tag>_K, merges them
 * and checks that the merge prints exactly what args alone print. */
static void check_shards_merge(const char *tag, const char *args, int nshards)
{
    char *full, *err, *out, cmd[2048], list[1024] = "";
    CHECK_INT(run(args, &full, &err), 0);
    free(err);
    for (int k = 1; k <= nshards; k++) {
        char path[128];
        snprintf(path, sizeof path, " %s/%s_%d", tmpdir, tag, k);
        snprintf(cmd, sizeof cmd, "(" PD_CLI_PATH " %s --shard %d/%d >%s)", args, k, nshards, path + 1);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
        free(out);
        free(err);
        strncat(list, path, sizeof list - strlen(list) - 1);
    }
    snprintf(cmd, sizeof cmd, "merge%s", list);
    CHECK_INT(run(cmd, &out, &err), 0);
    int same = strcmp(out, full) == 0 && full[0];
    if (!same)
        printf("     %s, %d shards: merged output differs from the run's:\n%s---\n%s", args,
               nshards, out, full);
    CHECK(same);
    free(out);
    free(err);
    free(full);
}

static void test_merge_equals_run(void)
{
    static const int counts[] = {1, 2, 3, 7};
    for (int i = 0; i < 4; i++) {
        check_shards_merge("uni", "-n 150 --seed 5 parts/cap.off", counts[i]);
        check_shards_merge("sta", "-n 140 --seed 2 --initial stationary " BOX, counts[i]);
    }
    /* Grouping happens at the merge, from the shards' per-pose counts. */
    check_shards_merge("grp", "-n 140 --initial stationary --group " BOX, 3);
    check_shards_merge("eng", "-n 40 --engine ode --dt 0.001 --mu 0.5 --units mm parts/block.stl", 3);
}

/* The side files: merge --transitions writes the unsharded run's chain; the
 * shards' --trials rows, sorted by drop, are the unsharded run's. A shard
 * with CR LF line ends merges as well. */
static void test_side_files(void)
{
    char cmd[2048], *out, *err;
    snprintf(cmd, sizeof cmd,
             "(set -e; P=" BOX "; B=" PD_CLI_PATH "; D=%s\n"
             "$B -n 140 --initial stationary --transitions $D/t.csv --trials $D/tr.csv $P >/dev/null\n"
             "$B -n 140 --initial stationary $P >$D/ts.csv\n"
             "for k in 1 2 3; do\n"
             "  $B -n 140 --initial stationary --shard $k/3 --trials $D/tr$k.csv $P >$D/ts$k.csv\n"
             "done\n"
             "$B merge --transitions $D/tm.csv $D/ts1.csv $D/ts2.csv $D/ts3.csv >/dev/null\n"
             "cmp $D/t.csv $D/tm.csv\n"
             "sed 's/$/\\r/' $D/ts2.csv >$D/ts2crlf.csv\n"
             "$B merge $D/ts1.csv $D/ts2crlf.csv $D/ts3.csv | cmp - $D/ts.csv\n"
             "(head -n 1 $D/tr.csv; cat $D/tr1.csv $D/tr2.csv $D/tr3.csv | grep -v '^drop' |"
             " sort -t, -k1,1n) | cmp - $D/tr.csv)", tmpdir);
    /* The box's stationary runs warn that the long run is fragile, as they
     * should; the warnings are shown only if the script fails. */
    int rc = run_cmd(cmd, 1, &out, &err);
    CHECK_INT(rc, 0);
    if (rc != 0)
        printf("     %s", err);
    free(out);
    free(err);
}

/* A shard's file, made once, for the refusals. */
static const char *shard(const char *name, const char *args)
{
    static char path[8][128];
    static int n;
    char cmd[1024], *out, *err;
    snprintf(path[n % 8], sizeof path[0], "%s/%s", tmpdir, name);
    snprintf(cmd, sizeof cmd, "(" PD_CLI_PATH " %s >%s)", args, path[n % 8]);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    return path[n++ % 8];
}

/* A copy of a shipped part in the scratch directory, at path. */
static void copy_part(const char *from, const char *name, char *path, size_t size)
{
    char cmd[512], *out, *err;
    snprintf(path, size, "%s/%s", tmpdir, name);
    snprintf(cmd, sizeof cmd, "cp %s %s", from, path);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
}

static void expect_merge_failure(const char *a, const char *b, const char *mention)
{
    char cmd[512];
    snprintf(cmd, sizeof cmd, "merge %s %s", a, b ? b : "");
    expect_failure(cmd, 2, mention);
}

static void test_merge_refusals(void)
{
    const char *s1 = shard("r1", "-n 30 --shard 1/2 parts/cap.off");
    const char *s2 = shard("r2", "-n 30 --shard 2/2 parts/cap.off");
    expect_merge_failure(s1, shard("part", "-n 30 --shard 2/2 parts/button.off"), "part=");
    expect_merge_failure(s1, shard("scene", "-n 30 --shard 2/2 -h 0.1 parts/cap.off"), "height=");
    expect_merge_failure(s1, shard("seed", "-n 30 --shard 2/2 --seed 9 parts/cap.off"), "seed=");
    expect_merge_failure(s1, shard("count", "-n 30 --shard 2/3 parts/cap.off"), "shard count");
    expect_merge_failure(s1, s1, "shard 1/2 again");
    expect_merge_failure(s2, NULL, "shard 1/2 is missing");
    expect_merge_failure(s1, "parts/paper-tables.csv", "not a shard");
    expect_merge_failure(s1, "/nonexistent/shard", "/nonexistent/shard");
    /* A named pipe no program writes to: refused at once, where open()
     * waited for a writer for ever (timeout ends a regression with 124). */
    char fifo[128], fcmd[512], *fout, *ferr;
    snprintf(fifo, sizeof fifo, "%s/nowriter", tmpdir);
    CHECK(mkfifo(fifo, 0600) == 0);
    snprintf(fcmd, sizeof fcmd, "timeout 60 %s merge %s %s", PD_CLI_PATH, s1, fifo);
    CHECK_INT(run_cmd(fcmd, 1, &fout, &ferr), 2);
    CHECK(strstr(ferr, "nowriter: a named pipe that gave nothing to read") != NULL);
    CHECK_INT((int)strlen(fout), 0);
    free(fout);
    free(ferr);
    remove(fifo);

    /* Another version's shard: its first line says so. */
    char path[128], cmd[512], *out, *err;
    snprintf(path, sizeof path, "%s/version", tmpdir);
    snprintf(cmd, sizeof cmd, "(sed '1s/^# posedrop [^ ]*/# posedrop 0.0.9/' %s >%s)", s2, path);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    expect_merge_failure(s1, path, "posedrop version");

    /* The part changed after the shards ran. */
    char part[128];
    copy_part("parts/cap.off", "moved.off", part, sizeof part);
    snprintf(cmd, sizeof cmd, "-n 20 --shard 1/1 %s", part);
    const char *moved = shard("moved", cmd);
    snprintf(cmd, sizeof cmd, "(echo '# touched' >>%s)", part);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    expect_merge_failure(moved, NULL, "has changed");

    expect_failure("--shard 1/2 --ci 0.05 parts/cap.off", 2, "--ci");
    expect_failure("--shard 1/2 --initial bootstrap -n 50 parts/cap.off", 2, "bootstrap");
    expect_failure("--shard 1/2 parts/cap.off", 2, "needs -n");
    expect_failure("--shard 0/2 -n 10 parts/cap.off", 2, "--shard");
    expect_failure("--shard 3/2 -n 10 parts/cap.off", 2, "--shard");
    expect_failure("--shard 1/0 -n 10 parts/cap.off", 2, "--shard");
    expect_failure("--shard 1 -n 10 parts/cap.off", 2, "--shard");
    expect_failure("--shard 1/2 --format json -n 10 parts/cap.off", 2, "--format json");
    expect_failure("--shard 1/2 --svg /tmp/posedrop-never.svg -n 10 parts/cap.off", 2, "pictures");
    expect_failure("merge", 2, "expected the shard files");
    expect_failure("merge --format xml x", 2, "--format");
}

/* merge writes no output onto its inputs: --transitions onto a shard, onto
 * the shards' part or onto merge's own standard output; each file stays as
 * it was, byte for byte, and nothing is printed. */
static void test_merge_same_file(void)
{
    char part[128], args[512], cmd[1024], *out, *err;
    copy_part(BOX, "box.off", part, sizeof part);
    snprintf(args, sizeof args, "-n 140 --initial stationary --shard 1/2 %s", part);
    const char *t1 = shard("st1", args);
    snprintf(args, sizeof args, "-n 140 --initial stationary --shard 2/2 %s", part);
    const char *t2 = shard("st2", args);
    char *shard1 = slurp(t1), *box = slurp(part);
    snprintf(args, sizeof args, "merge --transitions %s %s %s", t1, t1, t2);
    expect_failure(args, 2, "is the same file as shard");
    snprintf(args, sizeof args, "merge --transitions %s %s %s", part, t1, t2);
    expect_failure(args, 2, "is the same file as the shards' part");
    snprintf(cmd, sizeof cmd, "sh -c '" PD_CLI_PATH " merge --transitions %s/tm2.csv %s %s >>%s'",
             tmpdir, t1, t2, t1);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 2);
    CHECK(strstr(err, "standard output") != NULL);
    free(out);
    free(err);
    char *now1 = slurp(t1), *now_box = slurp(part);
    CHECK(shard1 && now1 && strcmp(shard1, now1) == 0);
    CHECK(box && now_box && strcmp(box, now_box) == 0);
    free(shard1);
    free(now1);
    free(box);
    free(now_box);
    /* posedrop-mpi shares the check. */
    if (access(PD_CLI_MPI_PATH, X_OK) == 0) {
        /* OpenMPI's own allocations outlive MPI_Finalize, as for MPIRUN_2. */
        snprintf(args, sizeof args, "ASAN_OPTIONS=detect_leaks=0 " PD_CLI_MPI_PATH
                 " -n 5 --trials %s %s", part, part);
        CHECK_INT(run_cmd(args, 1, &out, &err), 2);
        CHECK(out[0] == '\0' && strstr(err, "is the same file as PART") != NULL);
        free(out);
        free(err);
    }
}

/* SIGTERM stops a run as SIGINT does: the drops done are printed, marked
 * partial, exit 143; merge refuses such a shard. The run asks for far more
 * drops than finish before the signal (10^6 drops of the cap take minutes). */
static void test_sigterm(void)
{
    char cmd[512], *out, *err, path[128];
    snprintf(path, sizeof path, "%s/term", tmpdir);
    snprintf(cmd, sizeof cmd, "(timeout --preserve-status -s TERM 1 " PD_CLI_PATH
             " -n 1000000 -j 2 --shard 1/2 parts/cap.off >%s)", path);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 143);
    CHECK(strstr(err, "interrupted after") != NULL);
    free(out);
    free(err);
    char *csv = slurp(path);
    CHECK(csv && strstr(csv, ",1\n") != NULL); /* the partial column */
    free(csv);
    expect_merge_failure(path, NULL, "interrupted");
}

/* The progress line goes to a terminal only: none in a file, and under a
 * pseudo-terminal (script) a line whose last redraw counts every drop. */
static void test_progress(void)
{
    char *out, *err;
    CHECK_INT(run("-n 50 parts/cap.off", &out, &err), 0);
    CHECK(strstr(err, "drops/s") == NULL);
    free(out);
    free(err);
    if (access("/usr/bin/script", X_OK) != 0) {
        printf("     script(1) not found: progress on a terminal not checked\n");
        return;
    }
    CHECK_INT(run_cmd("script -qec '" PD_CLI_PATH " -n 50 -j 1 parts/cap.off >/dev/null' /dev/null",
                      1, &out, &err), 0);
    CHECK(strstr(out, "50 of 50 drops") != NULL && strstr(out, "drops/s") != NULL);
    free(out);
    free(err);
}

/* --format json parsed back: the rows equal the CSV's, column by column, the
 * metadata match the run (sha256 as Python's hashlib computes it). With jq
 * alone, the row count and the hash. */
static void test_json(void)
{
    char cmd[2048], *out, *err, csv[128], json[128], merged[128];
    snprintf(csv, sizeof csv, "%s/run.csv", tmpdir);
    snprintf(json, sizeof json, "%s/run.json", tmpdir);
    snprintf(merged, sizeof merged, "%s/merged.json", tmpdir);
    snprintf(cmd, sizeof cmd, "(" PD_CLI_PATH " -n 60 --units mm parts/block.stl >%s && " PD_CLI_PATH
             " --format json -n 60 --units mm parts/block.stl >%s && " PD_CLI_PATH
             " -n 60 --units mm --shard 1/2 parts/block.stl >%s.1 && " PD_CLI_PATH
             " -n 60 --units mm --shard 2/2 parts/block.stl >%s.2 && " PD_CLI_PATH
             " merge --format json %s.1 %s.2 >%s)", csv, json, merged, merged, merged, merged,
             merged);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    if (access("/usr/bin/python3", X_OK) == 0 || system("command -v python3 >/dev/null") == 0) {
        snprintf(cmd, sizeof cmd,
                 "python3 -c '\n"
                 "import csv, hashlib, json, sys\n"
                 "doc = json.load(open(sys.argv[2]))\n"
                 "merged = json.load(open(sys.argv[3]))\n"
                 "rows = list(csv.DictReader(open(sys.argv[1])))\n"
                 "assert len(rows) == len(doc[\"poses\"]) > 0\n"
                 "for r, p in zip(rows, doc[\"poses\"]):\n"
                 "    assert set(r) == set(p), (set(r), set(p))\n"
                 "    for k in r: assert float(r[k]) == p[k], (k, r[k], p[k])\n"
                 "assert merged[\"poses\"] == doc[\"poses\"]\n"
                 "part = doc[\"part\"]\n"
                 "assert part[\"sha256\"] == hashlib.sha256(open(\"parts/block.stl\", \"rb\").read()).hexdigest()\n"
                 "assert part[\"units\"] == \"mm\" and part[\"hull\"][\"facets\"] > 0\n"
                 "assert len(part[\"centre_of_mass_m\"]) == 3 and part[\"mass\"][\"volume_m3\"] > 0\n"
                 "d = doc[\"drops\"]\n"
                 "assert d[\"run\"] == 60 and d[\"requested\"] == 60 and d[\"seed\"] == 1\n"
                 "assert d[\"unsettled\"] == int(rows[0][\"unsettled\"]) and d[\"engine\"] == \"impulse\"\n"
                 "assert doc[\"posedrop\"][\"command_line\"][-1] == \"parts/block.stl\"\n"
                 "assert doc[\"posedrop\"][\"wall_s\"] >= 0 and doc[\"posedrop\"][\"cpu_s\"] > 0\n"
                 "assert merged[\"posedrop\"][\"merged_shards\"] is True\n"
                 "assert doc[\"scene\"][\"contact_time_auto\"] is True and doc[\"scene\"][\"contact_time_s\"] > 0\n"
                 "' %s %s %s", csv, json, merged);
    } else {
        snprintf(cmd, sizeof cmd, "jq -e --arg h \"$(sha256sum parts/block.stl | cut -c1-64)\" "
                 "'.part.sha256 == $h and (.poses | length) == %d' %s >/dev/null", 6, json);
    }
    /* The box's stationary runs warn that the long run is fragile, as they
     * should; the warnings are shown only if the script fails. */
    int rc = run_cmd(cmd, 1, &out, &err);
    CHECK_INT(rc, 0);
    if (rc != 0)
        printf("     %s", err);
    free(out);
    free(err);
}

/* scripts/slurm-array.sh against a stub sbatch that logs its arguments and
 * runs each job at once as Slurm would (every task of an array with its
 * SLURM_ARRAY_TASK_ID): the jobs it submits, their dependency, and a
 * result.csv equal to the run on one machine, for a part whose path holds a
 * space (the commands are quoted). */
static void test_slurm(void)
{
    char cmd[2048], *out, *err, *one;
    snprintf(cmd, sizeof cmd, "mkdir -p %s/bin && cp parts/cap.off '%s/my cap.off'", tmpdir, tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    snprintf(cmd, sizeof cmd, "%s/bin/sbatch", tmpdir);
    char stub[1024];
    snprintf(stub, sizeof stub,
             "#!/usr/bin/env bash\n"
             "printf '%%s\\n' \"$@\" -- >>%s/sbatch.log\n"
             "n=$(( $(grep -c '^--$' %s/sbatch.log) ))\n"
             "for a in \"$@\"; do case \"$a\" in --array=*) array=${a#--array=} ;;"
             " --wrap=*) wrap=${a#--wrap=} ;; esac; done\n"
             "if [ -n \"${array:-}\" ]; then\n"
             "  for k in $(seq ${array%%-*} ${array#*-}); do SLURM_ARRAY_TASK_ID=$k bash -c \"$wrap\" || exit 1; done\n"
             "else bash -c \"$wrap\" || exit 1; fi\n"
             "echo \"$((1000 + n));cluster\"\n", tmpdir, tmpdir);
    CHECK(write_file(cmd, stub));
    snprintf(cmd, sizeof cmd, "chmod +x %s/bin/sbatch && PATH=%s/bin:$PATH scripts/slurm-array.sh "
             "-N 3 -o %s/slurm -b " PD_CLI_PATH " -s '--time=10' -- -n 90 --seed 7 '%s/my cap.off'",
             tmpdir, tmpdir, tmpdir, tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    CHECK(strstr(out, "shards: job 1001 (array 1-3); merge: job 1002") != NULL);
    if (err[0])
        printf("     %s", err);
    free(out);
    free(err);
    snprintf(cmd, sizeof cmd, "%s/sbatch.log", tmpdir);
    char *log = slurp(cmd);
    CHECK(log && strstr(log, "--array=1-3\n") && strstr(log, "--time=10\n") &&
          strstr(log, "--dependency=afterok:1001\n") && strstr(log, "--cpus-per-task=1\n"));
    /* The merge job comes after the array, and names every shard. */
    const char *dep = log ? strstr(log, "--dependency") : NULL;
    CHECK(dep && strstr(dep, "merge") && strstr(dep, "shard_1.csv") && strstr(dep, "shard_3.csv"));
    free(log);
    snprintf(cmd, sizeof cmd, "-n 90 --seed 7 '%s/my cap.off'", tmpdir);
    CHECK_INT(run(cmd, &one, &err), 0);
    free(err);
    snprintf(cmd, sizeof cmd, "%s/slurm/result.csv", tmpdir);
    char *merged = slurp(cmd);
    CHECK(merged && one[0] && strcmp(merged, one) == 0);
    free(merged);
    free(one);
    /* Refused before anything is submitted. */
    snprintf(cmd, sizeof cmd, "PATH=%s/bin:$PATH scripts/slurm-array.sh -N 0 -- -n 9 parts/cap.off",
             tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 2);
    CHECK(strstr(err, "-N") != NULL);
    free(out);
    free(err);
}

/* As root, OpenMPI wants to be told; two ranks on fewer cores is fine here.
 * OpenMPI's own allocations outlive MPI_Finalize, which LeakSanitizer would
 * report under SANITIZE=1. */
#define MPIRUN_2 PD_MPIRUN " -n 2 --allow-run-as-root --oversubscribe -x ASAN_OPTIONS=detect_leaks=0 "

/* posedrop-mpi on two ranks prints the single process's bytes. */
static void test_mpi(void)
{
    if (access(PD_CLI_MPI_PATH, X_OK) != 0 || system("command -v " PD_MPIRUN " >/dev/null") != 0) {
        printf("     OpenMPI not installed: posedrop-mpi not checked (scripts/install-deps.sh mpi)\n");
        return;
    }
    static const char *const runs[] = {
        "-n 200 --seed 4 parts/cap.off",
        "-n 140 --initial stationary --group " BOX,
        "-n 30 --engine ode --dt 0.001 --units mm parts/block.stl",
    };
    for (int i = 0; i < 3; i++) {
        char cmd[512], *one, *two, *err;
        CHECK_INT(run(runs[i], &one, &err), 0);
        free(err);
        snprintf(cmd, sizeof cmd, MPIRUN_2 PD_CLI_MPI_PATH " %s", runs[i]);
        CHECK_INT(run_cmd(cmd, 1, &two, &err), 0);
        int same = strcmp(one, two) == 0 && one[0];
        if (!same)
            printf("     mpirun -n 2 %s differs from one process:\n%s---\n%s%s", runs[i], two, one,
                   err);
        CHECK(same);
        free(one);
        free(two);
        free(err);
    }
    char *out, *err;
    CHECK_INT(run_cmd(MPIRUN_2 PD_CLI_MPI_PATH " --ci 0.05 parts/cap.off", 1, &out, &err), 2);
    CHECK(out[0] == '\0' && strstr(err, "--ci") != NULL);
    free(out);
    free(err);
    /* The command's rules over ranks: an output on a named pipe that no
     * program reads is refused at once (each rank waited in open(2)). A
     * stdout that fails is mpirun's to see, not the ranks' (it forwards
     * their output), so that rule is checked on posedrop alone. */
    static const struct {
        const char *script;
        int code;
        const char *mention;
    } rules[] = {
        {"mkfifo f; timeout -s KILL 60 $M $B -n 5 --chart f $P", 2,
         "f: cannot write: a named pipe that no program is reading"},
    };
    for (size_t k = 0; k < sizeof rules / sizeof *rules; k++) {
        char cmd[1024];
        snprintf(cmd, sizeof cmd, "(R=$PWD; M='" MPIRUN_2 "'; B=$R/" PD_CLI_MPI_PATH "; "
                 "P=$R/parts/cap.off; D=%s/mpirule%zu; mkdir -p $D && cd $D && %s)", tmpdir, k,
                 rules[k].script);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), rules[k].code);
        if (!strstr(err, rules[k].mention))
            printf("     posedrop-mpi case %zu should say '%s':\n%s", k, rules[k].mention, err);
        CHECK(strstr(err, rules[k].mention) != NULL);
        free(out);
        free(err);
    }
}

/* The part's SHA-256 (shards, JSON) against coreutils' sha256sum, for files
 * whose length mod 64 falls on each side of the padding's boundaries (55,
 * 56: the length fits the last block or not; 63, 0, 1: a block ends). */
static void test_sha256(void)
{
    char cmd[1024], *out, *err;
    snprintf(cmd, sizeof cmd,
             "(set -e; for n in 119 120 127 128 129 183 184; do f=%s/pad$n.off\n"
             "  { printf 'OFF\\n4 4 0\\n0 0 0\\n1 0 0\\n0 1 0\\n0 0 1\\n3 0 2 1\\n3 0 1 3\\n"
             "3 0 3 2\\n3 1 2 3\\n#'; printf '%%0200d' 0; } | head -c $((n - 1)) >$f; echo >>$f\n"
             "  test $(wc -c <$f) -eq $n\n"
             "  " PD_CLI_PATH " --format json $f | grep -q \"\\\"sha256\\\": \\\"$(sha256sum $f | cut -c1-64)\\\"\"\n"
             "done)", tmpdir);
    /* The box's stationary runs warn that the long run is fragile, as they
     * should; the warnings are shown only if the script fails. */
    int rc = run_cmd(cmd, 1, &out, &err);
    CHECK_INT(rc, 0);
    if (rc != 0)
        printf("     %s", err);
    free(out);
    free(err);
}

/* posedrop's short forms through the batch: letters with their values glued
 * or not, prefixes of long names, '=': the same rows as posedrop's own run
 * with the full names, under a part column. */
static void test_batch_short_forms(void)
{
    char cmd[512], *out, *err, *bout, *berr;
    snprintf(cmd, sizeof cmd, "scripts/posedrop-batch -j1 -o %s/short -n25 -h 0.1 --see=3 "
             "--mu 0.4 -v -0.02 --init uniform -- parts/cap.off", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &bout, &berr), 0);
    CHECK_INT(run("-n 25 -h 0.1 --seed 3 --mu 0.4 -v -0.02 --initial uniform parts/cap.off",
                  &out, &err), 0);
    char path[160];
    snprintf(path, sizeof path, "%s/short/all.csv", tmpdir);
    char *all = slurp(path);
    /* all.csv: the command's rows, each after "cap,". */
    int rows = 0, same = all != NULL;
    const char *a = all ? strchr(all, '\n') : NULL, *o = strchr(out, '\n');
    while (same && a && o && a[1] && o[1]) {
        a++;
        o++;
        const char *ea = strchr(a, '\n'), *eo = strchr(o, '\n');
        same = ea && eo && strncmp(a, "cap,", 4) == 0 && ea - a - 4 == eo - o &&
               strncmp(a + 4, o, (size_t)(eo - o)) == 0;
        rows += same;
        a = ea;
        o = eo;
    }
    CHECK(same && rows > 1);
    free(all);
    free(out);
    free(err);
    free(bout);
    free(berr);

    /* A part that succeeds with a warning (a file in millimetres read as
     * metres) says so on the batch's stderr, and leaves no .err file:
     * those are for failures. */
    snprintf(cmd, sizeof cmd, "scripts/posedrop-batch -j1 -o %s/warn -- parts/block.stl", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &bout, &berr), 0);
    CHECK(strstr(berr, "block.stl: the part is 45.8 m across; if the file is in millimetres, "
                       "add --units mm") != NULL);
    snprintf(path, sizeof path, "%s/warn/block.err", tmpdir);
    CHECK(access(path, F_OK) != 0);
    snprintf(path, sizeof path, "%s/warn/block.csv", tmpdir);
    CHECK(access(path, F_OK) == 0);
    free(bout);
    free(berr);
}

/* A batch that fails or is stopped keeps every earlier result: a part's
 * DIR/<name>.csv until its new one is complete, all.csv until every part has
 * one, with the parts that failed or did not run named on stderr; nothing
 * temporary stays. SIGINT and SIGTERM reach the runs under way (10^6 drops
 * of the cap take minutes, so the signal always comes first). */
static void test_batch_keeps_results(void)
{
    char cmd[1024], *out, *err;
    snprintf(cmd, sizeof cmd, "(set -e; D=%s/keep; scripts/posedrop-batch -o $D/out -n 20 -- "
             "parts/cap.off parts/canonical/cube.off 2>/dev/null; cp -r $D/out $D/first)", tmpdir);
    CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
    free(out);
    free(err);
    static const struct {
        const char *run;
        int code;
        const char *mention;
    } cases[] = {
        {"scripts/posedrop-batch -o $D/out -n 20 --com 5,5,5 -- parts/cap.off "
         "parts/canonical/cube.off", 1, "parts/cap.off (failed), parts/canonical/cube.off (failed)"},
        {"timeout --preserve-status -s INT 2 scripts/posedrop-batch -j1 -o $D/out -n 1000000 -- "
         "parts/cap.off parts/canonical/cube.off", 130, "parts/canonical/cube.off (not run)"},
        {"timeout --preserve-status -s TERM 2 scripts/posedrop-batch -j2 -o $D/out -n 1000000 -- "
         "parts/cap.off parts/canonical/cube.off", 143, "(interrupted)"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        snprintf(cmd, sizeof cmd, "(D=%s/keep; %s)", tmpdir, cases[k].run);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), cases[k].code);
        if (!strstr(err, cases[k].mention))
            printf("     '%s' should say '%s':\n%s", cases[k].run, cases[k].mention, err);
        CHECK(strstr(err, cases[k].mention) != NULL);
        CHECK(strstr(err, "all.csv is left as it was") != NULL);
        free(out);
        free(err);
        /* The first run's files, byte for byte; besides them only .err files. */
        snprintf(cmd, sizeof cmd, "(set -e; D=%s/keep; for f in all cap cube; do cmp $D/first/$f.csv "
                 "$D/out/$f.csv; done; test -z \"$(ls $D/out | grep -v -e '\\.csv$' -e '\\.err$')\")",
                 tmpdir);
        int left = run_cmd(cmd, 1, &out, &err);
        if (left != 0) {
            char ls[512];
            snprintf(ls, sizeof ls, "ls -l %s/keep/out", tmpdir);
            printf("     after '%s': the first run's files changed or others left:\n%s%s",
                   cases[k].run, out, err);
            free(out);
            free(err);
            run_cmd(ls, 1, &out, &err);
            printf("%s%s", out, err);
        }
        CHECK_INT(left, 0);
        free(out);
        free(err);
    }
}

/* Every script under scripts/ refuses a bad argument with one line on stderr
 * that names the script and what was wrong, exit status 2, nothing on
 * stdout, and nothing left in the directory it ran in (the case:
 * posedrop-batch given options after --, which printed shell errors and left
 * all.csv.tmp and 1000.err behind). */
static void test_script_refusals(void)
{
    static const struct {
        const char *args, *mention;
    } cases[] = {
        {"posedrop-batch -j 2 -o results --units mm -- -n 1000 -- a.stl",
         "posedrop-batch: '-n' after --: options for posedrop go before --"},
        {"posedrop-batch -j x -- $R/parts/cap.off", "posedrop-batch: -j: expected a whole number"},
        {"posedrop-batch -o", "posedrop-batch: -o needs a value"},
        {"posedrop-batch -j -1 -- $R/parts/cap.off", "posedrop-batch: -j: expected a whole number"},
        {"posedrop-batch -o results -- a.stl", "posedrop-batch: a.stl: no such readable file"},
        {"posedrop-batch -o results -- $R/parts/cap.off $R/parts/cap.off", "two parts named 'cap'"},
        /* posedrop's options in the forms it takes (a prefix, '=', a letter
         * with its value glued or not) are the options they name. */
        {"posedrop-batch -o results --sens=t.csv --mu 0.2:0.4 -- $R/parts/cap.off "
         "$R/parts/button.off", "--sensitivity t.csv would be written by the run of each of the 2"},
        {"posedrop-batch -o results -n5 --tri t.csv -- $R/parts/cap.off $R/parts/button.off",
         "--trials t.csv would be written by the run of each of the 2 parts"},
        {"posedrop-batch -o results --s 3 -- $R/parts/cap.off",
         "option '--s' is the start of more than one of posedrop's options' names"},
        {"posedrop-batch -o results -x 3 -- $R/parts/cap.off", "unknown option '-x' for posedrop"},
        {"posedrop-batch -o results --fac=1 -- $R/parts/cap.off",
         "option '--facets' takes no value"},
        {"posedrop-batch -o results -h -- $R/parts/cap.off", "option '-h' needs a value"},
        {"collect-csv nofile.csv", "collect-csv: nofile.csv: no such readable file"},
        {"collect-csv", "collect-csv: no CSV files given"},
        {"cost-accuracy.sh -s 0", "cost-accuracy.sh: -s: expected a whole number"},
        {"cost-accuracy.sh -o", "cost-accuracy.sh: -o needs a value"},
        {"crosscheck.sh -n x $R/parts/cap.off", "crosscheck.sh: -n: expected a whole number"},
        {"crosscheck.sh -- --units", "crosscheck.sh: option '--units' needs a value"},
        /* After --, posedrop's flags take no value and the part files may
         * come among the options. */
        {"crosscheck.sh -- --group --units mm nofile.stl", "crosscheck.sh: nofile.stl: no such"},
        {"crosscheck.sh -- --units mm --group", "crosscheck.sh: no part files given"},
        {"crosscheck.sh -- --bogus 3 $R/parts/cap.off", "unknown option '--bogus' for posedrop"},
        {"crosscheck.sh -o out nofile.stl", "crosscheck.sh: nofile.stl: no such readable file"},
        {"figures.sh --x", "figures.sh: unknown argument '--x'"},
        {"demo.sh x", "demo.sh: expected POSEDROP PART [OUTDIR]"},
        {"demo.sh /bin/true nofile.off", "demo.sh: nofile.off: no such readable file"},
        {"paper.sh -i foo", "paper.sh: posedrop: --initial: initial: expected uniform, bootstrap"},
        {"paper.sh -n 0", "paper.sh: -n: expected a whole number"},
        {"paper.sh -L -H cap", "paper.sh: -H: expected one of insulator_cap"},
        {"paper.sh -L -P 0", "paper.sh: -P: expected a whole number"},
        {"paper.sh -L -s 1x", "paper.sh: -s: expected a whole number"},
        {"paper.sh -e odes", "paper.sh: -e: expected impulse, ode or bullet, got 'odes'"},
        {"figures.sh --cheap --x", "figures.sh: unknown argument '--x'"},
        {"doc_tables.py nosuch", "doc_tables.py: no table 'nosuch'"},
        {"sweeps.sh -p foo", "sweeps.sh: -p: expected mu, restitution, height or contact_time, got 'foo'"},
        {"slurm-array.sh -N", "slurm-array.sh: -N needs a value"},
        {"sensitivity.sh -n", "sensitivity.sh: -n needs a value"},
        {"sensitivity.sh -i foo $R/parts/cap.off", "sensitivity.sh: posedrop: --initial: initial"},
        {"fuzz.sh x off", "fuzz.sh: SECONDS: expected a whole number"},
        {"fuzz.sh 5 nosuch", "fuzz.sh: no target 'nosuch' built"},
        {"lint-layers.sh --x", "lint-layers.sh: takes no arguments"},
        {"install-deps.sh 'bad name'", "install-deps.sh: 'bad name' is not a Debian package name"},
        {"make-canonical.py a b", "make-canonical.py: expected at most one argument"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        char cmd[2048], *out, *err;
        /* An empty directory of its own; R is the repository. */
        snprintf(cmd, sizeof cmd,
                 "R=$PWD; d=%s/refuse%zu; mkdir $d && cd $d && $R/scripts/%s", tmpdir, k,
                 cases[k].args);
        int rc = run_cmd(cmd, 1, &out, &err);
        CHECK_INT(rc, 2);
        CHECK_INT((int)strlen(out), 0);
        const char *nl = strchr(err, '\n');
        int one_line = nl && nl[1] == '\0';
        if (!strstr(err, cases[k].mention) || !one_line)
            printf("     stderr of '%s' should be one line saying '%s':\n     %s", cases[k].args,
                   cases[k].mention, err);
        CHECK(strstr(err, cases[k].mention) && one_line);
        free(out);
        free(err);
        snprintf(cmd, sizeof cmd, "test -z \"$(ls -A %s/refuse%zu)\"", tmpdir, k);
        CHECK_INT(run_cmd(cmd, 1, &out, &err), 0);
        free(out);
        free(err);
    }
}

void suite_batch(void)
{
    snprintf(tmpdir, sizeof tmpdir, "/tmp/posedrop-batch-XXXXXX");
    if (!mkdtemp(tmpdir)) {
        CHECK(!"cannot create a temporary directory");
        return;
    }
    test_merge_equals_run();
    test_side_files();
    test_merge_refusals();
    test_merge_same_file();
    test_sigterm();
    test_progress();
    test_json();
    test_sha256();
    test_slurm();
    test_mpi();
    test_script_refusals();
    test_batch_short_forms();
    test_batch_keeps_results();
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", tmpdir);
    if (system(cmd) != 0)
        printf("     could not remove %s\n", tmpdir);
}
