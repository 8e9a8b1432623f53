/* test_fuzz_replay.c: every input the fuzz harness (make fuzz) keeps is
 * replayed by make check: the crashes it found (tests/fuzz/regressions/
 * TARGET/), its seeds (tests/fuzz/seeds/TARGET/) and the shipped parts, each
 * through the same target body (tests/support/fuzz_targets.c), which asks
 * for a well-formed answer: a valid mesh, scene or static estimate, or a
 * refusal with a message. Under the sanitizer build a crash here fails too. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "check.h"
#include "fuzz_targets.h"
#include "suites.h"

typedef int (*target_fn)(const uint8_t *, size_t);

/* Replays every regular file of dir; the number replayed. */
static int replay_dir(const char *dir, target_fn fn, const char *target)
{
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat sb;
        if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode))
            continue;
        FILE *f = fopen(path, "rb");
        if (!f)
            continue;
        fseek(f, 0, SEEK_END);
        long size = ftell(f);
        fseek(f, 0, SEEK_SET);
        uint8_t *buf = malloc((size_t)size + 1);
        size_t got = buf ? fread(buf, 1, (size_t)size, f) : 0;
        fclose(f);
        if (!buf || got != (size_t)size) {
            free(buf);
            continue;
        }
        int ok = fn(buf, got);
        if (!ok)
            printf("     fuzz target %s: answer not well-formed for %s\n", target, path);
        CHECK(ok);
        free(buf);
        n++;
    }
    closedir(d);
    return n;
}

void suite_fuzz_replay(void)
{
    static const struct {
        const char *name;
        target_fn fn;
        int parts; /* the shipped parts are seeds too */
    } targets[] = {{"off", pd_fuzz_off, 1},   {"stl", pd_fuzz_stl, 1},
                   {"obj", pd_fuzz_obj, 1},   {"scene", pd_fuzz_scene, 0},
                   {"part", pd_fuzz_part, 1}, {"api", pd_fuzz_api, 0},
                   {"measured", pd_fuzz_measured, 0}, {"shard", pd_fuzz_shard, 0}};
    for (size_t i = 0; i < sizeof targets / sizeof targets[0]; i++) {
        char dir[128];
        int n = 0;
        snprintf(dir, sizeof dir, "tests/fuzz/regressions/%s", targets[i].name);
        n += replay_dir(dir, targets[i].fn, targets[i].name);
        snprintf(dir, sizeof dir, "tests/fuzz/seeds/%s", targets[i].name);
        n += replay_dir(dir, targets[i].fn, targets[i].name);
        if (targets[i].parts) {
            n += replay_dir("parts", targets[i].fn, targets[i].name);
            n += replay_dir("parts/canonical", targets[i].fn, targets[i].name);
        }
        CHECK(n > 0); /* the files are where make fuzz looks for them */
    }
    /* The checks are not vacuous: a part's estimate is a distribution, a
     * refused input has a message, and a scene out of range is refused
     * unchanged. */
    const char *cube = "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
                       "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
    CHECK(pd_fuzz_part((const uint8_t *)cube, strlen(cube)));
    CHECK(pd_fuzz_part((const uint8_t *)"OFF\n4 4", 7));
    CHECK(pd_fuzz_scene((const uint8_t *)"mu = 11\n", 8));
}
