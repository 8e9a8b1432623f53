/* scene.h (private): scene text from memory, for the fuzz harness (a scene
 * file is otherwise read by path, pd_scene_read). */
#ifndef PD_SCENE_H
#define PD_SCENE_H

#include <stddef.h>
#include <stdint.h>
#include "posedrop/sim.h"

/* As pd_scene_read, from size bytes at data; name is used in messages. */
pd_status pd_scene_parse(const void *data, size_t size, const char *name, pd_scene *scene,
                         pd_diag *diag);

/* The axis of drop `drop`'s tumble (a unit vector uniform over the sphere),
 * from the parameters' stream of pd_scene_draw, after their draws. */
void pd_scene_tumble_axis(uint64_t seed, long drop, double axis[3]);

#endif
