/* test_drop_step.c: the stepping engines (ODE, Bullet) through the shared
 * drop loop: symmetric solids land uniformly, same seed gives the same
 * records whatever the thread count, and the drops settle. */
#include <stdlib.h>
#include <string.h>
#include "check.h"
#include "base/gsl_adapter.h"
#include "posedrop/posedrop.h"
#include "shapes.h"
#include "suites.h"
#include "base/vec3.h"

/* The solid, about 1 cm across, and its poses; 0 (a check counted) on
 * failure. */
static int solid_part(int (*solid)(pd_vec3 *), pd_part **part, pd_static_result **poses)
{
    pd_vec3 p[64];
    int n = solid(p);
    pd_mesh *m = convex_mesh(p, n);
    double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    if (m)
        mesh_transform(m, CR(I), 0.005, v3(0, 0, 0));
    *part = NULL;
    *poses = NULL;
    int ok = m && pd_part_build(m, NULL, part, NULL) == PD_OK &&
             pd_static_estimate(*part, NULL, poses, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    return ok;
}

static pd_sim_options drop_options(pd_engine_kind engine, long drops)
{
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.ndrops = drops;
    return o;
}

static void run_solid(pd_engine_kind engine, int (*solid)(pd_vec3 *), long drops)
{
    pd_part *part;
    pd_static_result *poses;
    int ok = solid_part(solid, &part, &poses);
    pd_sim_options o = drop_options(engine, drops);
    o.keep_trials = 1;
    o.threads = 1;
    pd_sim_result *a = NULL, *b = NULL;
    pd_diag d;
    pd_diag_init(&d);
    if (ok)
        CHECK_STATUS(pd_sim_run(part, poses, NULL, &o, &a, &d), PD_OK);
    o.threads = 2;
    if (ok)
        CHECK_STATUS(pd_sim_run(part, poses, NULL, &o, &b, &d), PD_OK);
    if (a && b) {
        /* Uniform within the 99.9% chi-square bound (fixed seed: the verdict
         * is reproducible; a false alarm once in a thousand seeds). */
        CHECK(uniform_p_value(a) > 1e-3);
        /* A soft engine may leave a few drops rocking at the time limit, but
         * they are counted, and nearly all settle. */
        CHECK(a->unsettled <= drops / 50);
        CHECK(memcmp(a->count, b->count, sizeof *a->count * (size_t)a->nposes) == 0);
        /* Field by field: the record's padding is not part of the result. */
        long differ = 0;
        for (long i = 0; i < a->n; i++) {
            const pd_trial *x = &a->trials[i], *y = &b->trials[i];
            differ += memcmp(x->q0, y->q0, sizeof x->q0) != 0 || x->pose != y->pose ||
                      x->collisions != y->collisions || x->time != y->time || x->end != y->end;
        }
        if (differ)
            printf("     engine %d: %ld of %ld records differ between 1 and 2 threads\n",
                   (int)engine, differ, a->n);
        CHECK_INT(differ, 0);
    }
    pd_sim_result_free(a);
    pd_sim_result_free(b);
    pd_static_result_free(poses);
    pd_part_free(part);
}

/* A cube's faces are alike, so whatever the engine each takes 1/6 of the
 * drops; an engine that treats the part's own axes differently shows it here
 * (Bullet's plane probes did: chi-square 41.5 on 1200 drops of seed 5). 1200
 * drops detect a face share off by 0.03 from 1/6 (0.14 against 0.19) with
 * the 99.9% chi-square bound; fixed seed, so the verdict is reproducible. */
static void cube_uniform(pd_engine_kind engine)
{
    pd_part *part;
    pd_static_result *poses;
    int ok = solid_part(pts_cube, &part, &poses);
    pd_sim_options o = drop_options(engine, 1200);
    o.seed = 5;
    o.threads = 2;
    pd_sim_result *r = NULL;
    if (ok)
        CHECK_STATUS(pd_sim_run(part, poses, NULL, &o, &r, NULL), PD_OK);
    if (r) {
        CHECK_INT(r->nposes, 6);
        double pv = uniform_p_value(r);
        if (!(pv > 1e-3))
            printf("     engine %d: cube faces not uniform, chi-square p %.3g\n", (int)engine, pv);
        CHECK(pv > 1e-3);
        CHECK(r->unsettled <= o.ndrops / 50);
    }
    pd_sim_result_free(r);
    pd_static_result_free(poses);
    pd_part_free(part);
}

void suite_drop_step(void)
{
    const pd_engine_kind engines[] = {PD_ENGINE_ODE, PD_ENGINE_BULLET};
    for (int e = 0; e < 2; e++) {
        run_solid(engines[e], pts_cube, 300);
        run_solid(engines[e], pts_octahedron, 300);
        cube_uniform(engines[e]);
    }
}
