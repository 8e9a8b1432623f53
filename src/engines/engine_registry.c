/* engine_registry.c: the stepping engines this program can run.
 *
 * ODE is part of libposedrop. Bullet is C++, so it lives in its own library,
 * libposedrop-bullet, whose pd_bullet_register hands its table over here: a C
 * program that never asks for Bullet then links neither Bullet nor the C++
 * runtime, and one that asks without registering gets PD_ERR_UNAVAILABLE. */
#include <stdatomic.h>
#include <string.h>
#include "engines/engine.h"
#include "posedrop/version.h"

/* Atomic so that registering on one thread while another runs drops is
 * defined; a run reads it once, when it builds its model. */
static _Atomic(const pd_engine *) bullet;

pd_status pd_engine_register(pd_engine_kind kind, const pd_engine *engine, const char *version)
{
    if (kind != PD_ENGINE_BULLET || !engine || !version)
        return PD_ERR_USAGE;
    /* The table's layout is private and may change with any version: only
     * the libposedrop-bullet built with this libposedrop may register. */
    if (strcmp(version, PD_VERSION_STRING) != 0)
        return PD_ERR_UNAVAILABLE;
    atomic_store(&bullet, engine);
    return PD_OK;
}

const pd_engine *pd_engine_get(pd_engine_kind kind)
{
    if (kind == PD_ENGINE_ODE)
        return &pd_engine_ode;
    if (kind == PD_ENGINE_BULLET)
        return atomic_load(&bullet);
    return NULL;
}

int pd_engine_available(pd_engine_kind kind)
{
    return kind == PD_ENGINE_IMPULSE || pd_engine_get(kind) != NULL;
}
