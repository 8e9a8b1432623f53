/* drop_fixture.c: see drop_fixture.h. */
#include <math.h>
#include <string.h>
#include "check.h"
#include "drop_fixture.h"
#include "base/quat.h"
#include "shapes.h"
#include "base/vec3.h"

int drop_setup(drop_fixture *fx, pd_mesh *mesh, const pd_scene *sc)
{
    memset(fx, 0, sizeof *fx);
    pd_sim_options o;
    pd_sim_options_default(&o);
    int ok = pd_part_build(mesh, NULL, &fx->part, NULL) == PD_OK &&
             pd_static_estimate(fx->part, NULL, &fx->poses, NULL) == PD_OK &&
             pd_sim_model_build(fx->part, fx->poses, sc, &o, &fx->model, NULL) == PD_OK &&
             (fx->work = pd_drop_work_alloc(fx->model, sc)) != NULL;
    pd_mesh_free(mesh);
    CHECK(ok);
    return ok;
}

const pd_body *drop_setup_box(drop_fixture *fx, pd_scene *sc, double mu)
{
    pd_scene_default(sc);
    sc->mu = mu;
    if (!drop_setup(fx, mesh_box(0.01, 0.02, 0.03), sc))
        return NULL;
    return (fx->model)->body;
}

void drop_teardown(drop_fixture *fx)
{
    pd_drop_work_free(fx->work);
    pd_sim_model_free(fx->model);
    pd_static_result_free(fx->poses);
    pd_part_free(fx->part);
}

int lowest_vertices(const pd_body *b, pd_quat q, int *out)
{
    double zmin = 1e300;
    for (int i = 0; i < b->nverts; i++)
        zmin = fmin(zmin, quat_rotate(q, b->verts[i]).z);
    int n = 0;
    for (int i = 0; i < b->nverts; i++)
        if (quat_rotate(q, b->verts[i]).z < zmin + 1e-12)
            out[n++] = i;
    return n;
}

double kinetic_energy(const pd_body *b, const pd_state *s)
{
    return 0.5 * b->mass * v3_dot(s->v, s->v) +
           0.5 * (b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                  b->moment[2] * s->w.z * s->w.z);
}

pd_quat quat_onto_down(pd_vec3 n)
{
    pd_vec3 down = v3(0, 0, -1), axis = v3_cross(n, down);
    double s = v3_norm(axis), c = v3_dot(n, down);
    if (s > 1e-12)
        return quat_axis_angle(v3_scale(axis, 1.0 / s), atan2(s, c));
    return c > 0 ? quat_identity() : quat_axis_angle(v3(1, 0, 0), M_PI);
}

double total_energy(const pd_body *b, double g, const pd_state *s)
{
    return kinetic_energy(b, s) + b->mass * g * s->x.z;
}

void state_gap_add(state_gap *gap, const pd_body *b, double g, const pd_state *a,
                   const pd_state *r)
{
    double L = b->size, T = sqrt(L / g), V0 = L / T, mgL = b->mass * g * L;
    double Ea = total_energy(b, g, a), Er = total_energy(b, g, r);
    gap->x = fmax(gap->x, v3_dist(a->x, r->x) / L);
    gap->v = fmax(gap->v, v3_dist(a->v, r->v) / V0);
    gap->q = fmax(gap->q, fmax(fmax(fabs(a->q.w - r->q.w), fabs(a->q.x - r->q.x)),
                               fmax(fabs(a->q.y - r->q.y), fabs(a->q.z - r->q.z))));
    gap->w = fmax(gap->w, v3_dist(a->w, r->w) * T);
    gap->E = fmax(gap->E, fabs(Ea - Er) / mgL);
}

void state_gap_check(const state_gap *gap, double tol)
{
    CHECK_NEAR(gap->x, 0.0, tol, "position per L");
    CHECK_NEAR(gap->v, 0.0, tol, "velocity per sqrt(g L)");
    CHECK_NEAR(gap->q, 0.0, tol, "unit quaternion components");
    CHECK_NEAR(gap->w, 0.0, tol, "rate of turn per 1/sqrt(L/g)");
    CHECK_NEAR(gap->E, 0.0, tol, "energy per m g L");
}
