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

static void run_solid(pd_engine_kind engine, int (*solid)(pd_vec3 *), long drops)
{
    pd_vec3 p[64];
    int n = solid(p);
    pd_mesh *m = convex_mesh(p, n);
    double I[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    mesh_transform(m, CR(I), 0.005, v3(0, 0, 0)); /* about 1 cm across */
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    int ok = pd_part_build(m, NULL, &part, NULL) == PD_OK &&
             pd_static_estimate(part, NULL, &poses, NULL) == PD_OK;
    pd_mesh_free(m);
    CHECK(ok);
    pd_sim_options o;
    pd_sim_options_default(&o);
    o.engine = engine;
    o.ndrops = drops;
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

void suite_drop_step(void)
{
    const pd_engine_kind engines[] = {PD_ENGINE_ODE, PD_ENGINE_BULLET};
    /* As a program linked with libposedrop-bullet does (test_api checks the
     * status without it). */
    CHECK_STATUS(pd_bullet_register(), PD_OK);
    for (int e = 0; e < 2; e++) {
        run_solid(engines[e], pts_cube, 300);
        run_solid(engines[e], pts_octahedron, 300);
    }
}
