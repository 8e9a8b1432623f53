/* stages.c: where the static pipeline's time goes on a mesh file, stage by
 * stage: CPU seconds of this process (user + sys) spent reading the file
 * and in each stage of pd_part_build as its stage callback names them,
 * the centre of mass given as the origin (as `posedrop --com 0,0,0`). Built
 * and run by scripts/bigmesh-table.sh against the library of the posedrop
 * it measures; prints one row of a Markdown table per file. */
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "posedrop/posedrop.h"

static const char *const names[] = {"welding", "convex hull", "orienting", "mass properties",
                                    "self-crossing check"};
enum { NSTAGES = 5 };

static double cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct clockbook {
    double at, spent[NSTAGES];
    int cur; /* the running stage, -1 before the first */
} clockbook;

static void on_stage(void *user, const char *name)
{
    clockbook *b = user;
    double t = cpu();
    if (b->cur >= 0)
        b->spent[b->cur] += t - b->at;
    b->at = t;
    b->cur = -1;
    for (int i = 0; i < NSTAGES; i++)
        if (strcmp(name, names[i]) == 0)
            b->cur = i;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: stages MESH...\n");
        return 2;
    }
    for (int f = 1; f < argc; f++) {
        pd_mesh_read_options ro;
        pd_mesh_read_options_default(&ro);
        pd_mesh *m = NULL;
        double t0 = cpu();
        if (pd_mesh_read(argv[f], &ro, &m, NULL) != PD_OK) {
            fprintf(stderr, "stages: cannot read %s\n", argv[f]);
            return 1;
        }
        double read = cpu() - t0;
        clockbook b = {cpu(), {0}, -1};
        pd_part_options po;
        pd_part_options_default(&po);
        po.com_given = 1;
        po.com = (pd_vec3){0, 0, 0};
        po.stage = on_stage;
        po.stage_user = &b;
        pd_part *p = NULL;
        pd_status st = pd_part_build_take(&m, &po, &p, NULL);
        on_stage(&b, "");
        double total = cpu() - t0;
        const char *base = strrchr(argv[f], '/');
        printf("| %s | %.2f |", base ? base + 1 : argv[f], read);
        for (int i = 0; i < NSTAGES; i++)
            printf(" %.2f |", b.spent[i]);
        printf(" %.2f |%s\n", total, st == PD_OK ? "" : " (not built)");
        pd_part_free(p);
        pd_mesh_free(m);
    }
    return 0;
}
