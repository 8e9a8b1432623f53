/* posedrop/sim.h: the dynamic estimator: Monte Carlo drops of the part on a
 * flat floor (paper, section 5).
 *
 * Each drop releases the part above the floor and follows it through flight
 * and frictional collisions until its outcome can no longer change: its total
 * energy is below the lowest energy barrier of the basin it is in, so the
 * stable pose of that basin is where it ends. Drops are independent: drop i
 * draws from its own random stream derived from (seed, i), so results do not
 * depend on the number of threads or their scheduling. */
#ifndef POSEDROP_SIM_H
#define POSEDROP_SIM_H

#include <stdint.h>
#include "posedrop/diag.h"
#include "posedrop/part.h"
#include "posedrop/static.h"
#include "posedrop/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum pd_restitution_law {
    PD_RESTITUTION_POISSON = 0, /* normal impulse at maximum compression times (1 + e) */
    PD_RESTITUTION_ENERGETIC    /* Stronge: restitution work = e^2 compression work */
} pd_restitution_law;

typedef enum pd_initial {
    PD_INITIAL_UNIFORM = 0, /* orientation uniform over SO(3) */
    PD_INITIAL_BOOTSTRAP    /* the paper's: resting poses drawn from the running estimate */
} pd_initial;

/* What a drop is made of. Filled by pd_scene_default, then edited. */
typedef struct pd_scene {
    double height;          /* m, lowest point of the part above the floor at release; 0.12 */
    double belt_speed;      /* m/s, horizontal velocity at release (along x); 0.05 */
    double mu;              /* Coulomb friction part-floor; 0.3 */
    double restitution;     /* coefficient of restitution e in [0, 1]; 0.3 */
    pd_restitution_law law; /* PD_RESTITUTION_POISSON */
    double vibration;       /* rad: each initial pose turned by up to this about a random axis; 1.5 deg */
    pd_initial initial;     /* PD_INITIAL_UNIFORM */
    double gravity;         /* m/s^2; 9.81 */
} pd_scene;

void pd_scene_default(pd_scene *scene);

/* Sets one setting by name, as in a scene file or on a command line:
 * height, belt_speed (or v), mu, restitution, restitution_law
 * (poisson|energetic), vibration (degrees), initial (uniform|bootstrap),
 * gravity. PD_ERR_USAGE for an unknown key, PD_ERR_PARSE for a bad value,
 * PD_ERR_RANGE for a value out of range; the scene is unchanged on failure. */
pd_status pd_scene_set(pd_scene *scene, const char *key, const char *value, pd_diag *diag);

/* Reads "key = value" lines ('#' comments, blank lines) into scene, on top of
 * what it holds. Errors name the file and line. */
pd_status pd_scene_read(const char *path, pd_scene *scene, pd_diag *diag);

#ifdef __cplusplus
}
#endif
#endif
