/* settle.h (private): when a drop's outcome is decided, and what resting
 * contact is; shared by the impulse simulator's drop loop, its contact
 * phases and the stepping engines' drop.
 *
 * A drop is decided when its energy per unit weight (a height) falls below
 * the barrier of the basin it is in (basin.h): no future can then leave the
 * basin, so that basin's stable pose is the outcome. The basin is where
 * quasi-static descent from the present orientation lands (descent_map.h).
 * Built once per run from the part and shared read-only by every thread. */
#ifndef PD_SETTLE_H
#define PD_SETTLE_H

#include "dynamics/body.h"
#include "posedrop/static.h"
#include "settle/descent_map.h"
#include "settle/flat_rest.h"
#include "static/static_internal.h"

typedef struct pd_settle {
    const pd_body *body;        /* the part in principal axes (not owned) */
    const pd_static_result *poses; /* the caller's pose table (not owned) */
    pd_static_result *descent;  /* the exact quasi-static rest[] of every facet */
    double *barrier;            /* per facet: its basin's barrier height, m */
    double barrier_max;         /* the largest of them */
    pd_flat_facet *flat;        /* per facet: what lying flat on it takes (flat_rest.h) */
    double flat_height;         /* m: with the centre of mass this high, flat on none */
    pd_star star;
    pd_descent_map map;         /* the descent, looked up */
    int *pose_of;               /* facet -> pose index in poses, or -1 */
    double rest_fall;           /* m: how far resting contact falls between microcollisions */
    double margin;              /* m: how low a state's energy may read (the
                                   engine's resting contact may sink that far):
                                   the energy test passes below the barrier
                                   less this */
    double still;               /* m: with the energy less than this above
                                   lying on the pose of the basin it is in, the
                                   part lies still there as far as the engine
                                   can tell (pd_settle_outcome); 0: no such
                                   test */
    double v_rest;              /* approach speeds up to this are resting contact (e = 0) */
    double patch;               /* m: the radius of the contact patch under the
                                   part's weight, whose friction resists spin
                                   about the floor's normal (docs/contact.md,
                                   "Drilling friction"); 0: a point contact */
} pd_settle;

/* Builds everything the test needs for part (whose rigid body is body) and
 * the pose table poses, under gravity (m/s^2). PD_ERR_NOMEM, or the
 * statuses of the static estimator; *settle is freed on failure. */
pd_status pd_settle_build(const pd_part *part, const pd_body *body, const pd_static_result *poses,
                          double gravity, pd_settle *settle, pd_diag *diag);
void pd_settle_free(pd_settle *settle);

/* 1 and the pose index if the outcome of state s is decided, 0 if not yet,
 * -1 on failure (of the descent, which is not taken when the energy is above
 * every barrier). hint speeds up successive calls. */
int pd_settle_decided(const pd_settle *settle, const pd_state *s, double gravity, int *hint,
                      int *pose);

/* pd_settle_decided, also giving the facet the part would land on, or -1
 * when neither that test nor pd_flat_settled can pass (the energy above
 * every barrier, the centre of mass above every flat rest's reach), where
 * the descent is skipped. */
int pd_settle_decided_at(const pd_settle *settle, const pd_state *s, double gravity, int *hint,
                         int *pose, int *facet);

/* The outcome test of a drop in state s: pd_settle_decided_at, or lying
 * flat on a stable facet that sliding and spinning (friction mu) cannot tip
 * it from (pd_flat_settled), or its energy within settle->still of lying on
 * the pose of the basin it is in. The last adds decisions only where that
 * basin's barrier is below the pose's height plus still plus margin (a
 * higher one has the energy test pass first): basins the engine cannot tell
 * apart, such as two stable facets meeting at a ridge of 0.1 degree. 1 and
 * *pose when decided, 0 if not yet, -1 on failure. */
int pd_settle_outcome(const pd_settle *settle, const pd_state *s, double gravity, double mu,
                      int *hint, int *pose);

/* The part's tilt in state s from the facet of pose: the angle between
 * gravity and that facet's normal, rad. */
double pd_settle_tilt(const pd_settle *settle, const pd_state *s, int pose);

#endif
