/* settle.c: when a drop's outcome is decided (see settle.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "base/quat.h"
#include "base/vec3.h"
#include "posedrop/tolerances.h"
#include "settle/basin.h"
#include "settle/settle.h"

void pd_settle_free(pd_settle *st)
{
    pd_static_result_free(st->descent);
    free(st->barrier);
    free(st->flat);
    pd_descent_map_free(&st->map);
    pd_star_free(&st->star);
    free(st->pose_of);
    memset(st, 0, sizeof *st);
}

pd_status pd_settle_build(const pd_part *part, const pd_body *body, const pd_static_result *poses,
                          double gravity, pd_settle *st, pd_diag *diag)
{
    memset(st, 0, sizeof *st);
    st->body = body;
    st->poses = poses;
    /* Basins follow the exact motion whatever rule the static table used;
     * stability, hence the set of poses, is the same under both rules. */
    pd_static_options so;
    pd_static_options_default(&so);
    so.topple = PD_TOPPLE_DESCENT;
    so.epsilon = 0.0;
    /* The estimate that made poses has given the part's warnings (knife
     * edges) already; this one, of the same part, would repeat them. */
    pd_diag quiet;
    pd_diag_init(&quiet);
    pd_status s = pd_static_estimate(part, &so, &st->descent, &quiet);
    if (s != PD_OK)
        pd_fail(diag, s, "%s", quiet.message);
    if (s == PD_OK)
        s = pd_star_build(part->hull, &st->star);
    if (s == PD_OK)
        s = pd_descent_map_build(part->hull, &st->star, part->com, &st->map);
    int nf = part->hull->nfacets;
    if (s == PD_OK) {
        st->barrier = malloc(sizeof *st->barrier * (size_t)nf);
        st->pose_of = malloc(sizeof *st->pose_of * (size_t)nf);
        st->flat = malloc(sizeof *st->flat * (size_t)nf);
        if (!st->barrier || !st->pose_of || !st->flat)
            s = pd_fail(diag, PD_ERR_NOMEM, "out of memory for the drop model");
    }
    if (s != PD_OK) {
        pd_settle_free(st);
        return s;
    }
    pd_basin_barriers(part->hull, part->com, st->descent, st->barrier);
    pd_flat_build(body, part->hull, st->descent, st->flat);
    st->flat_height = pd_flat_height_max(st->flat, nf);
    st->barrier_max = -INFINITY;
    for (int f = 0; f < nf; f++) {
        st->pose_of[f] = -1;
        st->barrier_max = fmax(st->barrier_max, st->barrier[f]);
    }
    for (int k = 0; k < poses->nposes; k++)
        st->pose_of[poses->poses[k].facet] = k;
    /* A resting vertex meets the floor at the speed of falling rest_fall;
     * twice that leaves room for what the part's rotation adds. */
    st->rest_fall = PD_TOL_REST_FALL_REL * body->size;
    st->v_rest = 2.0 * sqrt(2.0 * gravity * st->rest_fall);
    st->margin = st->rest_fall;
    st->still = 0.0;
    st->patch = 0.0;
    return PD_OK;
}

/* Energy per unit weight: the height the part could reach, m. */
static double energy_height(const pd_body *b, const pd_state *s, double g)
{
    double rot = b->moment[0] * s->w.x * s->w.x + b->moment[1] * s->w.y * s->w.y +
                 b->moment[2] * s->w.z * s->w.z;
    return s->x.z + (v3_dot(s->v, s->v) + rot / b->mass) / (2.0 * g);
}

/* Gravity's direction in the part's (file) frame. */
static pd_vec3 gravity_in_part(const pd_settle *st, const pd_state *s)
{
    return quat_rotate(st->body->frame, quat_rotate_inv(s->q, v3(0, 0, -1)));
}

int pd_settle_decided_at(const pd_settle *st, const pd_state *s, double g, int *hint, int *pose,
                         int *facet)
{
    *facet = -1;
    if (!(energy_height(st->body, s, g) + st->margin < st->barrier_max) &&
        !(s->x.z < st->flat_height))
        return 0;
    pd_vec3 down = gravity_in_part(st, s);
    int f;
    if (pd_descent_lookup(&st->map, down, &f, hint) != PD_OK)
        return -1;
    *facet = f;
    /* A resting vertex may be up to rest_fall below the floor, so the part's
     * potential energy may read that much low: count it. */
    if (!(energy_height(st->body, s, g) + st->margin < st->barrier[f]))
        return 0;
    *pose = st->pose_of[st->descent->facets[f].rest];
    return *pose >= 0 ? 1 : -1;
}

int pd_settle_decided(const pd_settle *st, const pd_state *s, double g, int *hint, int *pose)
{
    /* Above every barrier nothing is decided, whichever basin s is in: the
     * descent, most of the test's cost, is left out (most of a contact
     * phase's tests, which come after every step, are up there). */
    if (!(energy_height(st->body, s, g) + st->margin < st->barrier_max))
        return 0;
    int f;
    return pd_settle_decided_at(st, s, g, hint, pose, &f);
}

int pd_settle_outcome(const pd_settle *st, const pd_state *s, double g, double mu, int *hint,
                      int *pose)
{
    int facet, d = pd_settle_decided_at(st, s, g, hint, pose, &facet);
    if (d == 0 && facet >= 0 && st->pose_of[facet] >= 0 &&
        pd_flat_settled(st->flat, st->body, s, facet, g, mu, st->margin)) {
        *pose = st->pose_of[facet];
        return 1;
    }
    if (d == 0 && facet >= 0 && st->still > 0.0) {
        int p = st->pose_of[st->descent->facets[facet].rest];
        if (p >= 0 && energy_height(st->body, s, g) < st->poses->poses[p].height + st->still) {
            *pose = p;
            return 1;
        }
    }
    return d;
}

double pd_settle_tilt(const pd_settle *st, const pd_state *s, int pose)
{
    return v3_angle(gravity_in_part(st, s), st->poses->poses[pose].normal);
}
