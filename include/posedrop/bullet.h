/* posedrop/bullet.h: the Bullet stepping engine, in its own library.
 *
 * Bullet is C++. It lives in libposedrop-bullet rather than in libposedrop,
 * so a C program that never asks for PD_ENGINE_BULLET links neither Bullet nor
 * the C++ runtime. A program that wants it links libposedrop-bullet
 * (pkg-config --libs posedrop-bullet) and calls pd_bullet_register() once,
 * before pd_sim_run with PD_ENGINE_BULLET; without it, pd_sim_run returns
 * PD_ERR_UNAVAILABLE for that engine and pd_engine_available says 0. */
#ifndef POSEDROP_BULLET_H
#define POSEDROP_BULLET_H

#include "posedrop/export.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Makes PD_ENGINE_BULLET available to pd_sim_run in this program. Safe to
 * call more than once. PD_ERR_UNAVAILABLE if this libposedrop-bullet was
 * built for another version of libposedrop. Defined in libposedrop-bullet. */
PD_API pd_status pd_bullet_register(void);

#ifdef __cplusplus
}
#endif
#endif
