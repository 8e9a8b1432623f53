/* engine_steps.h: the fixed steps at which the tests of robustness,
 * determinism, limits and pinned outcomes run the stepping engines: their
 * former defaults, ODE 1 ms and Bullet 1/960 s. Those tests are about every
 * drop ending, the same bytes and the refusals, which hold at any step; the
 * automatic step (pd_sim_options.dt 0, 20 steps per contact time) costs 20
 * to 40 times as many steps for centimetre parts, and has tests of its own
 * (test_drop_step.c, "auto step"). */
#ifndef PD_TEST_ENGINE_STEPS_H
#define PD_TEST_ENGINE_STEPS_H

#include "posedrop/sim.h"

static inline double test_engine_dt(pd_engine_kind engine)
{
    return engine == PD_ENGINE_ODE ? 1e-3 : engine == PD_ENGINE_BULLET ? 1.0 / 960.0 : 0.0;
}

#endif
