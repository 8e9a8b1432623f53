/* test_golden.c: pinned outcomes. Fixed seeded runs of shipped parts (the
 * static estimators, and drops on the impulse and ODE engines from uniform and
 * stationary starts) are hashed and compared with tests/golden.csv, so that a
 * refactor which claims to change nothing is checked, not trusted.
 *
 * A change of results that is meant (a new model, a fixed bug) re-pins them:
 * `make golden` runs this suite with PD_GOLDEN_WRITE set to the file, prints
 * every case whose hash moved and rewrites the file; the commit says why.
 *
 * The hash is FNV-1a over the bytes of every number that the run returns, in
 * a fixed little-endian layout: each drop's initial quaternion, pose,
 * collisions, simulated time and end, and the counts and probabilities. The
 * build compiles without contraction or reassociation (Makefile), so the
 * bytes do not depend on the optimisation level or the sanitizers; they may
 * differ with another libm or another ODE build, which is what re-pinning on
 * purpose is for. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "engine_steps.h"
#include "posedrop/posedrop.h"
#include "suites.h"

#define GOLDEN_FILE "tests/golden.csv"
#define GOLDEN_CASES_MAX 64

typedef struct {
    uint64_t h;
} fnv;

static void fnv_init(fnv *f)
{
    f->h = 0xcbf29ce484222325u;
}

static void fnv_u64(fnv *f, uint64_t x)
{
    for (int i = 0; i < 8; i++) {
        f->h ^= (x >> (8 * i)) & 0xffu;
        f->h *= 0x100000001b3u;
    }
}

static void fnv_i64(fnv *f, long long x)
{
    fnv_u64(f, (uint64_t)x);
}

static void fnv_f64(fnv *f, double x)
{
    uint64_t u;
    memcpy(&u, &x, sizeof u);
    fnv_u64(f, u);
}

typedef struct {
    char name[64];
    char hash[17];
} golden_row;

typedef struct {
    golden_row pinned[GOLDEN_CASES_MAX], now[GOLDEN_CASES_MAX];
    int npinned, nnow;
} golden_table;

static void read_pinned(golden_table *t)
{
    FILE *fp = fopen(GOLDEN_FILE, "r");
    if (!fp)
        return;
    char line[256];
    while (fgets(line, sizeof line, fp) && t->npinned < GOLDEN_CASES_MAX) {
        golden_row *r = &t->pinned[t->npinned];
        if (sscanf(line, "%63[^,],%16s", r->name, r->hash) == 2 && strcmp(r->name, "case") != 0)
            t->npinned++;
    }
    fclose(fp);
}

static const char *pinned_hash(const golden_table *t, const char *name)
{
    for (int i = 0; i < t->npinned; i++)
        if (strcmp(t->pinned[i].name, name) == 0)
            return t->pinned[i].hash;
    return NULL;
}

/* Compares (or, when writing, records) one case's hash. */
static void pin(golden_table *t, const char *name, uint64_t h, int writing)
{
    if (t->nnow >= GOLDEN_CASES_MAX) {
        CHECK(!"more golden cases than GOLDEN_CASES_MAX");
        return;
    }
    golden_row *r = &t->now[t->nnow++];
    snprintf(r->name, sizeof r->name, "%s", name);
    snprintf(r->hash, sizeof r->hash, "%016llx", (unsigned long long)h);
    const char *old = pinned_hash(t, name);
    if (writing) {
        if (!old)
            printf("golden: %s pinned as %s (new)\n", name, r->hash);
        else if (strcmp(old, r->hash) != 0)
            printf("golden: %s changed %s -> %s\n", name, old, r->hash);
        return;
    }
    if (!old || strcmp(old, r->hash) != 0)
        printf("     golden case %s: hash %s, pinned %s (make golden re-pins on purpose)\n",
               name, r->hash, old ? old : "none");
    CHECK(old && strcmp(old, r->hash) == 0);
}

typedef struct {
    pd_part *part;
    pd_static_result *poses;
} golden_part;

static int load(golden_part *g, const char *path)
{
    memset(g, 0, sizeof *g);
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    int ok = pd_mesh_read(path, NULL, &m, &d) == PD_OK &&
             pd_part_build(m, NULL, &g->part, &d) == PD_OK &&
             pd_static_estimate(g->part, NULL, &g->poses, &d) == PD_OK;
    pd_mesh_free(m);
    if (!ok)
        printf("     %s: %s\n", path, d.message);
    CHECK(ok);
    return ok;
}

static uint64_t hash_static(const pd_static_result *r)
{
    fnv f;
    fnv_init(&f);
    fnv_i64(&f, r->nposes);
    for (int i = 0; i < r->nposes; i++) {
        const pd_pose *p = &r->poses[i];
        fnv_f64(&f, p->normal.x);
        fnv_f64(&f, p->normal.y);
        fnv_f64(&f, p->normal.z);
        fnv_f64(&f, p->p_qs);
        fnv_f64(&f, p->p_pqs);
    }
    return f.h;
}

static uint64_t hash_sim(const pd_sim_result *r)
{
    fnv f;
    fnv_init(&f);
    fnv_i64(&f, r->n);
    fnv_i64(&f, r->unsettled);
    fnv_i64(&f, r->energy_gain);
    fnv_i64(&f, r->fallbacks);
    fnv_i64(&f, r->collisions);
    for (int k = 0; k < r->nposes; k++) {
        fnv_i64(&f, r->count[k]);
        fnv_f64(&f, r->p[k]);
        fnv_f64(&f, r->ci_lo[k]);
        fnv_f64(&f, r->ci_hi[k]);
    }
    for (long i = 0; i < r->n; i++) {
        const pd_trial *t = &r->trials[i];
        for (int c = 0; c < 4; c++)
            fnv_f64(&f, t->q0[c]);
        fnv_i64(&f, t->pose);
        fnv_i64(&f, t->collisions);
        fnv_f64(&f, t->time);
        fnv_i64(&f, t->end);
    }
    return f.h;
}

static void run_case(golden_table *t, int writing, const char *part_name, const golden_part *g,
                     pd_engine_kind engine, pd_initial initial, long ndrops)
{
    pd_scene sc;
    pd_scene_default(&sc);
    sc.initial = initial;
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.dt = test_engine_dt(engine);
    o.ndrops = ndrops;
    o.seed = 2026;
    o.threads = 2; /* any count gives the same bytes (test_sim); two exercises the split */
    o.keep_trials = 1;
    pd_sim_result *r = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_status st = pd_sim_run(g->part, g->poses, &sc, &o, &r, &d);
    char name[64];
    snprintf(name, sizeof name, "%s/%s/%s", part_name,
             engine == PD_ENGINE_IMPULSE ? "impulse" : "ode",
             initial == PD_INITIAL_UNIFORM ? "uniform" : "stationary");
    if (st != PD_OK)
        printf("     %s: %s (%s)\n", name, pd_status_str(st), d.message);
    CHECK_STATUS(st, PD_OK);
    if (st == PD_OK && r)
        pin(t, name, hash_sim(r), writing);
    pd_sim_result_free(r);
}

static void write_table(const golden_table *t, const char *path)
{
    FILE *fp = fopen(path, "w");
    CHECK(fp != NULL);
    if (!fp)
        return;
    fprintf(fp, "case,hash\n");
    for (int i = 0; i < t->nnow; i++)
        fprintf(fp, "%s,%s\n", t->now[i].name, t->now[i].hash);
    CHECK(fclose(fp) == 0);
    printf("golden: %d cases written to %s\n", t->nnow, path);
}

void suite_golden(void)
{
    /* Drop counts: enough that every pose and the drop loop's branches
     * (flight, collisions, contact phases, flat rest) are exercised, few
     * enough for the sanitizer build; a stationary run needs 10 drops per
     * pose and as many uniform ones (sim.h). */
    static const struct {
        const char *name, *path;
        long uniform, stationary;
    } parts[] = {
        {"cube", "parts/canonical/cube.off", 300, 70},
        {"box", "parts/canonical/box_1x2x3.off", 300, 70},
        {"coin", "parts/canonical/coin_h0.25.off", 200, 0},
        {"cap", "parts/cap.off", 150, 0},
    };
    const char *write_path = getenv("PD_GOLDEN_WRITE");
    int writing = write_path && *write_path;
    static golden_table t;
    memset(&t, 0, sizeof t);
    read_pinned(&t);
    if (!writing)
        CHECK(t.npinned > 0); /* a missing file is a failure, never a silent pass */

    for (size_t i = 0; i < sizeof parts / sizeof parts[0]; i++) {
        golden_part g;
        if (!load(&g, parts[i].path))
            continue;
        char name[64];
        snprintf(name, sizeof name, "%s/static", parts[i].name);
        pin(&t, name, hash_static(g.poses), writing);
        long stationary = 10 * (long)(g.poses->nposes + 1);
        if (parts[i].stationary > stationary)
            stationary = parts[i].stationary;
        for (int e = 0; e < 2; e++) {
            pd_engine_kind engine = e ? PD_ENGINE_ODE : PD_ENGINE_IMPULSE;
            run_case(&t, writing, parts[i].name, &g, engine, PD_INITIAL_UNIFORM, parts[i].uniform);
            run_case(&t, writing, parts[i].name, &g, engine, PD_INITIAL_STATIONARY, stationary);
        }
        pd_static_result_free(g.poses);
        pd_part_free(g.part);
    }
    if (writing) {
        for (int i = 0; i < t.npinned; i++) {
            int kept = 0;
            for (int j = 0; j < t.nnow; j++)
                kept |= strcmp(t.pinned[i].name, t.now[j].name) == 0;
            if (!kept)
                printf("golden: %s no longer run (removed)\n", t.pinned[i].name);
        }
        write_table(&t, write_path);
    } else {
        CHECK_INT(t.nnow, t.npinned); /* every pinned case still runs */
    }
}
