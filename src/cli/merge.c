/* merge.c: posedrop merge, the subcommand that sums the shards of one run
 * (shard.c reads and checks them) and prints through cli_run what the
 * unsharded run prints. */
#include <errno.h>
#include <getopt.h>
#include <stdlib.h>
#include <string.h>
#include "cli/cli.h"
#include "cli/command.h"
#include "cli/merge.h"

static void merge_usage(FILE *out)
{
    fprintf(out,
        "usage: %s merge [options] SHARD...\n"
        "\n"
        "Sums the shards that 'posedrop --shard K/N' printed, K = 1..N of one run,\n"
        "and prints exactly what the run without --shard prints. The part file\n"
        "named in the shards must still be there, unchanged (its SHA-256).\n"
        "\n"
        "  --format F         csv (default) or json\n"
        "  --transitions FILE with --initial stationary, the estimated chain as CSV\n"
        "  --verbose          a summary of the part and of the drops on stderr\n"
        "  --help             this help\n"
        "\n"
        "exit status: 0 success, 2 shards that do not make one whole run (other\n"
        "parts, scenes, seeds, versions or shard counts, a shard missing, twice or\n"
        "interrupted) or a bad file, 1 internal failure\n", prog);
}

int cli_merge(int argc, char **argv)
{
    enum { M_FORMAT = 256, M_TRANSITIONS, M_VERBOSE, M_HELP };
    static const struct option longopts[] = {
        {"format", required_argument, 0, M_FORMAT},
        {"transitions", required_argument, 0, M_TRANSITIONS},
        {"verbose", no_argument, 0, M_VERBOSE},
        {"help", no_argument, 0, M_HELP},
        {0, 0, 0, 0},
    };
    cli_args a;
    memset(&a, 0, sizeof a);
    pd_mesh_read_options_default(&a.read);
    pd_part_options_default(&a.part);
    pd_static_options_default(&a.estimate);
    pd_scene_default(&a.scene);
    pd_sim_options_default(&a.sim);
    a.argc = argc;
    a.argv = argv;
    opterr = 0;
    optind = 1;
    int c;
    while ((c = getopt_long(argc, argv, ":", longopts, NULL)) != -1) {
        switch (c) {
        case M_FORMAT:
            if (strcmp(optarg, "csv") != 0 && strcmp(optarg, "json") != 0) {
                fprintf(stderr, "%s: merge: --format: expected csv or json, got '%s'\n", prog,
                        optarg);
                return EXIT_USAGE;
            }
            a.json = strcmp(optarg, "json") == 0;
            break;
        case M_TRANSITIONS: a.transitions = optarg; break;
        case M_VERBOSE: a.verbose = 1; break;
        case M_HELP: merge_usage(stdout); return 0;
        case ':':
            fprintf(stderr, "%s: merge: option '%s' needs a value\n", prog, argv[optind - 1]);
            return EXIT_USAGE;
        default:
            fprintf(stderr, "%s: merge: unknown option '%s'\n%s: see '%s merge --help'\n", prog,
                    argv[optind - 1], prog, prog);
            return EXIT_USAGE;
        }
    }
    if (optind >= argc) {
        fprintf(stderr, "%s: merge: expected the shard files\n%s: see '%s merge --help'\n", prog,
                prog, prog);
        return EXIT_USAGE;
    }
    int nshard_files = argc - optind;
    static char path[1100];
    char sha[65], now[65];
    int ok = shard_load(argv + optind, nshard_files, &a, path, sizeof path, sha);
    if (ok && a.transitions && a.scene.initial != PD_INITIAL_STATIONARY) {
        fprintf(stderr, "%s: %s: --transitions needs the shards of a run with --initial "
                "stationary\n", prog, argv[optind]);
        ok = 0;
    }
    if (ok && !sha256_file(path, now)) {
        fprintf(stderr, "%s: %s: cannot read the shards' part: %s\n", prog, path, strerror(errno));
        ok = 0;
    }
    if (ok && strcmp(now, sha) != 0) {
        fprintf(stderr, "%s: %s: the part has changed since the shards ran (SHA-256 %s, the "
                "shards name %s)\n", prog, path, now, sha);
        ok = 0;
    }
    int code = EXIT_USAGE;
    /* The shards and their part are inputs; --transitions the one output. */
    if (ok && !(a.files = calloc((size_t)nshard_files + 2, sizeof *a.files))) {
        fprintf(stderr, "%s: out of memory\n", prog);
        code = EXIT_INTERNAL;
        ok = 0;
    }
    if (ok) {
        for (int i = 0; i < nshard_files; i++)
            a.files[a.nfiles++] = (cli_file){"shard", argv[optind + i], 0, 0};
        a.files[a.nfiles++] = (cli_file){"the shards' part", path, 0, 0};
        if (a.transitions)
            a.files[a.nfiles++] = (cli_file){"transitions", a.transitions, 1, 1};
        a.dynamic = 1;
        a.merge = argv + optind;
        code = cli_run(&a);
    }
    free(a.files);
    shard_unload();
    return code;
}
